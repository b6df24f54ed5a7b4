//! Random fleet scenarios of any size, for scaling runs (`generate`, `bench-scale`,
//! `bench-telemetry`). The same seed gives the same file.
//!
//! Two layouts ([`Layout`]), both with starts along the west side at 1200–1700 m height, goals
//! along the east side at 300–600 m height, hard and soft spheres (radius 60–150 m, 50 m
//! inflation) in the middle of the area, none touching a start or a goal, and AUVs with Zhi &
//! Zuo's limits (1–3 knots, ±35° turn, ±20° pitch, d_min 50 m). The mission time lets the longest
//! straight path be flown at 75 % of top speed.
//!
//! - **Crossing**: a square area 4 km wide and 2 km deep (z up, the surface at 2000 m), wider
//!   for a fleet of more than 24 so the starts stay three d_min apart ([`side`]), goals in a
//!   shuffled order so every path may cross every other. A bigger fleet is a bigger problem per
//!   vehicle too: longer paths past more spheres, and about N/4 crossings each.
//! - **Lanes**: a strip 4 km long, its width growing with the fleet ([`lanes_width`]), goals
//!   shuffled within groups of four neighbouring lanes. Each vehicle's problem stays the same
//!   size whatever the fleet: the same length, the same density of spheres, at most three
//!   crossings. It is how the cost of the planner itself grows with the fleet.

use std::fmt::Write as _;

use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use shoal_common::scenario::KNOT_MPS;

/// How a generated fleet is laid out (see the module's documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Layout {
    /// Every goal anywhere on the east side: paths cross all over the area.
    #[default]
    Crossing,
    /// Goals shuffled within groups of four neighbouring lanes of a 4 km strip.
    Lanes,
}

impl Layout {
    /// The start of a generated scenario's name and file name: `generated-N` or
    /// `generated-lanes-N`.
    pub fn stem(self) -> &'static str {
        match self {
            Layout::Crossing => "generated",
            Layout::Lanes => "generated-lanes",
        }
    }
}

/// Lanes whose goals are shuffled among themselves in the lanes layout.
const LANE_GROUP: usize = 4;

/// Side of the area up to 24 vehicles, metres.
const SMALL_SIDE: f64 = 4000.0;
const DEPTH: f64 = 2000.0;
const D_MIN: f64 = 50.0;
const INFLATION: f64 = 50.0;

/// Side of the square area for `n` vehicles, metres: 4 km, or wider so that the starts, spread
/// along a side less 200 m at each end, are at least 3 d_min apart (a 100-vehicle fleet packed
/// into 4 km would start 36 m apart, closer than d_min, and no plan could separate them).
pub fn side(n: usize) -> f64 {
    SMALL_SIDE.max(lanes_width(n))
}

/// Width of the lanes layout's strip for `n` vehicles, metres: lanes three d_min apart and
/// 200 m to spare at each side (the crossing layout's side beyond 24 vehicles too).
pub fn lanes_width(n: usize) -> f64 {
    400.0 + 3.0 * D_MIN * n as f64
}

/// The scenario text for `vehicles` vehicles and `spheres` hard and soft spheres each, laid
/// out as `layout`.
pub fn scenario_text(vehicles: u32, spheres: u32, seed: u64, layout: Layout) -> String {
    let mut rng = StdRng::seed_from_u64(seed);
    let n = vehicles as usize;
    let (length, width) = match layout {
        Layout::Crossing => (side(n), side(n)),
        Layout::Lanes => (SMALL_SIDE, lanes_width(n)),
    };
    let spacing = (width - 400.0) / n as f64;
    let starts: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let y = 200.0 + spacing * (i as f64 + 0.5);
            [150.0, y, rng.random_range(1200.0..1700.0)]
        })
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    match layout {
        Layout::Crossing => order.shuffle(&mut rng),
        Layout::Lanes => order
            .chunks_mut(LANE_GROUP)
            .for_each(|g| g.shuffle(&mut rng)),
    }
    let goals: Vec<[f64; 3]> = order
        .iter()
        .map(|&k| {
            let y = 200.0 + spacing * (k as f64 + 0.5);
            [length - 150.0, y, rng.random_range(300.0..600.0)]
        })
        .collect();
    let ends: Vec<[f64; 3]> = starts.iter().chain(&goals).copied().collect();
    let mut text = header(vehicles, spheres, seed, layout, [length, width]);
    let mut placed = 0;
    let mut tries = 0;
    let mut spheres_at: Vec<([f64; 3], f64)> = Vec::new();
    while placed < 2 * spheres as usize && tries < 10_000 {
        tries += 1;
        let r = rng.random_range(60.0..150.0);
        let c = [
            rng.random_range(0.2 * length..0.8 * length),
            rng.random_range(0.1 * width..0.9 * width),
            rng.random_range(400.0..1600.0),
        ];
        let clear = |p: &[f64; 3], room: f64| {
            let d: f64 = (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>().sqrt();
            d > r + INFLATION + room
        };
        if !ends.iter().all(|p| clear(p, 100.0))
            || !spheres_at.iter().all(|(q, rq)| clear(q, *rq + INFLATION))
        {
            continue;
        }
        spheres_at.push((c, r));
        let (kind, id) = if placed % 2 == 0 {
            ("hard", format!("H{}", placed / 2 + 1))
        } else {
            ("soft", format!("S{}", placed / 2 + 1))
        };
        let _ = writeln!(
            text,
            "[[obstacles]]\nid = \"{id}\"\nkind = \"{kind}\"\ncentre = [{:.1}, {:.1}, {:.1}]\nradius_m = {r:.1}\ninflation_m = {INFLATION:.1}\n",
            c[0], c[1], c[2]
        );
        placed += 1;
    }
    let (vmin, vmax) = (KNOT_MPS, 3.0 * KNOT_MPS);
    let mut longest: f64 = 0.0;
    for (i, (s, g)) in starts.iter().zip(&goals).enumerate() {
        longest = longest.max((0..3).map(|k| (g[k] - s[k]).powi(2)).sum::<f64>().sqrt());
        let _ = writeln!(
            text,
            "[[vehicles]]\nid = \"auv{}\"\nkind = \"auv\"\nstart = [{:.1}, {:.1}, {:.1}]\ngoal = [{:.1}, {:.1}, {:.1}]\n\
             speed_min_mps = {vmin}\nspeed_max_mps = {vmax}\nmax_turn_deg = 35.0\nmax_pitch_deg = 20.0\n",
            i + 1,
            s[0], s[1], s[2], g[0], g[1], g[2]
        );
    }
    let mission = (longest / (0.75 * vmax)).ceil();
    let _ = writeln!(
        text,
        "[fleet]\nd_min_m = {D_MIN:.1}\nmission_time_s = {mission:.1}\n\n[optimizer]\nseed = 1\n"
    );
    text
}

/// The file's opening comment, name, description and bounds.
fn header(vehicles: u32, spheres: u32, seed: u64, layout: Layout, size: [f64; 2]) -> String {
    let [length, width] = size;
    let (km_x, km_y) = (length / 1000.0, width / 1000.0);
    let name = layout.stem();
    let (flag, goals) = match layout {
        Layout::Crossing => ("", "in a\n# shuffled order"),
        Layout::Lanes => (
            " --layout lanes",
            "shuffled\n# within groups of four neighbouring lanes",
        ),
    };
    let spheres_where = "random hard and soft spheres in the middle. AUV limits as Zhi & Zuo 2024.";
    format!(
        "# Generated by `shoal-coordinator generate --vehicles {vehicles} --spheres {spheres} --seed {seed}{flag}`:\n\
         # a {km_x} x {km_y} km area 2 km deep, starts along the west side, goals along the east side {goals}, {spheres_where}\n\
         name = \"{name}-{vehicles}\"\n\
         description = \"{vehicles} AUVs, {spheres} hard and {spheres} soft spheres, layout seed {seed}\"\n\n\
         [bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [{length:.1}, {width:.1}, {DEPTH:.1}]\n\n"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::scenario::Scenario;

    #[test]
    fn generated_scenarios_load_and_keep_their_promises() -> anyhow::Result<()> {
        for n in [1, 8, 32, 100] {
            let text = scenario_text(n, 4, 3, Layout::Crossing);
            let s = Scenario::parse(&text, std::path::Path::new("gen.toml"))?;
            assert_eq!(s.vehicles.len(), n as usize);
            assert_eq!(s.obstacles.len(), 8);
            assert!(s.bounds.max[0] >= side(n as usize) - 1e-9);
            // Starts are at least d_min apart, and no start or goal is near a sphere.
            for (i, a) in s.vehicles.iter().enumerate() {
                for b in &s.vehicles[i + 1..] {
                    assert!((a.start() - b.start()).norm() >= D_MIN);
                }
                for o in &s.obstacles {
                    for p in [a.start(), a.goal()] {
                        assert!((p - o.centre()).norm() > o.inflated_radius() + 100.0);
                    }
                }
            }
            // The same seed gives the same file.
            assert_eq!(text, scenario_text(n, 4, 3, Layout::Crossing));
        }
        Ok(())
    }

    #[test]
    fn lanes_keep_every_vehicle_s_problem_the_same_size() -> anyhow::Result<()> {
        for n in [4, 8, 32, 100] {
            let text = scenario_text(n, n / 2, 1, Layout::Lanes);
            let s = Scenario::parse(&text, std::path::Path::new("lanes.toml"))?;
            assert_eq!(s.name, format!("generated-lanes-{n}"));
            assert_eq!(s.bounds.max[0], SMALL_SIDE);
            assert_eq!(s.bounds.max[1], 400.0 + 150.0 * n as f64);
            for (i, v) in s.vehicles.iter().enumerate() {
                // Lane i starts at 275 + 150 i and ends in a lane of its own group of four.
                assert!((v.start()[1] - (275.0 + 150.0 * i as f64)).abs() < 1e-9);
                let lane = ((v.goal()[1] - 275.0) / 150.0).round() as usize;
                assert_eq!(lane / LANE_GROUP, i / LANE_GROUP, "vehicle {i}");
                // The same crossing for every fleet: 3.7 km east, at most 450 m sideways.
                let d = v.goal() - v.start();
                assert!((d[0] - 3700.0).abs() < 1e-9 && d[1].abs() <= 450.0 + 1e-9);
                for o in &s.obstacles {
                    for p in [v.start(), v.goal()] {
                        assert!((p - o.centre()).norm() > o.inflated_radius() + 100.0);
                    }
                }
            }
            // One sphere of each kind per two vehicles, all placed.
            assert_eq!(s.obstacles.len(), 2 * (n as usize / 2));
        }
        Ok(())
    }
}
