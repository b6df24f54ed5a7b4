//! A scenario and a plan for it with hand-computed figures, shared by the checker's unit tests.

/// True when `a` and `b` are within `eps`.
pub(crate) fn approx(a: f64, b: f64, eps: f64) -> bool {
    (a - b).abs() <= eps
}

/// Two vehicles passing, one hard and one soft obstacle.
pub(crate) const SCENARIO: &str = r#"
name = "hand"
description = "two vehicles passing, one hard and one soft obstacle"
[bounds]
min = [0.0, -500.0, 0.0]
max = [1000.0, 500.0, 100.0]
[[obstacles]]
id = "H"
kind = "hard"
centre = [500.0, -60.0, 50.0]
radius_m = 20.0
inflation_m = 10.0
[[obstacles]]
id = "S"
kind = "soft"
centre = [250.0, 200.0, 50.0]
radius_m = 10.0
inflation_m = 10.0
[[vehicles]]
id = "a"
kind = "auv"
start = [0.0, 0.0, 50.0]
goal = [1000.0, 0.0, 50.0]
speed_min_mps = 0.5
speed_max_mps = 2.0
max_turn_deg = 35.0
max_pitch_deg = 20.0
[[vehicles]]
id = "b"
kind = "auv"
start = [1000.0, 200.0, 50.0]
goal = [0.0, 200.0, 50.0]
speed_min_mps = 0.5
speed_max_mps = 2.0
max_turn_deg = 35.0
max_pitch_deg = 20.0
[fleet]
d_min_m = 150.0
mission_time_s = 1000.0
[optimizer]
seed = 4
"#;

/// A plan for [`SCENARIO`] with hand-computed figures: a passes 60 m from H (clearance 40 m),
/// b 260 m (clearance 240 m) and straight through S (chord 2 · 20 = 40 m); both fly 1000 m
/// at 1 m/s and pass 200 m apart at t = 500 s.
pub(crate) fn plan_json(a_length: f64, feasible: bool, violations: &str, b_goal_x: f64) -> String {
    format!(
        r#"{{
  "scenario": "hand", "algorithm": "amp-pso", "mode": "in-process", "seed": 4,
  "runtime_s": 0.1, "fitness": 1.0, "objective": 1.0, "penalty": 0.0,
  "feasible": {feasible}, "violations": {violations}, "notices": [],
  "mission_time_s": 1000.0, "common_arrival_s": 1000.0, "d_min_m": 150.0,
  "iterations": 1, "evaluations": 1, "termination": "iterations",
  "vehicles": [
    {{"id": "a", "trajectory": [[0, 0, 0, 50], [500, 500, 0, 50], [1000, 1000, 0, 50]],
      "length_m": {a_length}, "arrival_s": 1000, "max_turn_deg": 0, "max_pitch_deg": 0,
      "min_speed_mps": 1, "max_speed_mps": 1, "min_clearance_m": 40, "hard_collisions": 0,
      "soft_exposure_m": 0}},
    {{"id": "b", "trajectory": [[0, 1000, 200, 50], [1000, {b_goal_x}, 200, 50]],
      "length_m": 1000, "arrival_s": 1000, "max_turn_deg": 0, "max_pitch_deg": 0,
      "min_speed_mps": 1, "max_speed_mps": 1, "min_clearance_m": 240, "hard_collisions": 0,
      "soft_exposure_m": 40}}
  ],
  "fleet": {{"min_separation_m": 200, "min_separation_pair": ["a", "b"],
    "min_separation_time_s": 500, "separation_breach_s": 0, "hard_collisions": 0,
    "arrival_spread_s": 0}},
  "convergence": [2.0, 1.0]
}}"#
    )
}
