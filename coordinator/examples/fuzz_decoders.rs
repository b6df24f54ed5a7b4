//! The fuzz run of the wire decoders: at least a million inputs per decoder — random bytes
//! and valid encodings mutated (bytes changed, inserted, removed, cut short), from a seeded
//! RNG — each decoded inside `catch_unwind`. Prints inputs per second per decoder and exits
//! with status 1 if any input panicked.
//!
//! ```text
//! cargo run --release -p shoal-coordinator --example fuzz_decoders [-- INPUTS [SEED]]
//! ```
//!
//! The test suite runs the same properties with a few thousand cases
//! (`common/src/wire/codec/tests/fuzz.rs`).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Instant;

use shoal_common::execution::{VehicleState, VehicleStatus};
use shoal_common::scenario::{Obstacle, ObstacleKind};
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;
use shoal_common::wire::codec::{decode, decode_json, encode, encode_json};
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::open::{FleetStatus, Telemetry, VehicleStatusRow, OPEN_VERSION};
use shoal_common::wire::{Envelope, WireChromosome, WireTrajectory, PROTOCOL_VERSION};
use shoal_coordinator::commands::serve::Submission;

/// splitmix64: small, seeded, good enough to pick bytes.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// One decoder under test: its name, valid encodings to mutate, and whether its input starts
/// with the protocol version (random inputs then carry it half the time, to get past it).
struct Target {
    name: &'static str,
    seeds: Vec<Vec<u8>>,
    versioned: bool,
    decode: fn(&[u8]) -> bool,
}

fn input(t: &Target, rng: &mut Rng, buf: &mut Vec<u8>) {
    buf.clear();
    if rng.next().is_multiple_of(2) {
        if t.versioned && rng.next().is_multiple_of(2) {
            buf.extend_from_slice(&PROTOCOL_VERSION.to_le_bytes());
        }
        let n = rng.below(256);
        buf.extend((0..n).map(|_| rng.next() as u8));
        return;
    }
    buf.extend_from_slice(&t.seeds[rng.below(t.seeds.len())]);
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(buf.len());
        let value = rng.next() as u8;
        match rng.next() % 5 {
            0 | 1 if !buf.is_empty() => buf[at] = value,
            2 => buf.insert(at, value),
            3 if !buf.is_empty() => {
                buf.remove(at);
            }
            _ => buf.truncate(at),
        }
    }
}

fn state() -> VehicleState {
    VehicleState {
        t_s: 1234.5,
        position: [100.0, -20.5, 180.0],
        velocity: [1.5, 0.1, 0.0],
        heading_deg: 3.8,
        depth_m: Some(220.0),
        altitude_m: None,
        battery: 0.93,
        status: VehicleStatus::Underway,
        arrived_s: None,
    }
}

fn bincode<T: serde::Serialize>(m: T) -> Vec<u8> {
    encode(&Envelope::sequenced(m, 42)).unwrap_or_default()
}

fn targets() -> Vec<Target> {
    let trajectory = WireTrajectory {
        vehicle: "auv1".into(),
        samples: vec![[0.0, 1.0, 2.0, 3.0], [10.0, 11.0, 12.0, 13.0]],
    };
    let telemetry = Telemetry {
        version: OPEN_VERSION,
        mission: "m1".into(),
        vehicle: "auv1".into(),
        seq: 17,
        revision: 2,
        sent_unix_us: 1_700_000_000_000_000,
        state: state(),
        command: None,
    };
    let status = FleetStatus {
        version: OPEN_VERSION,
        mission: "m1".into(),
        t_s: 1234.5,
        d_min_m: 50.0,
        vehicles: vec![VehicleStatusRow {
            vehicle: "auv1".into(),
            state: Some(state()),
            progress: None,
            revision: 2,
            silent_s: 0.4,
            lost: false,
            command: None,
        }],
        current_min_separation_m: Some(120.0),
        current_pair: Some(["auv1".into(), "auv2".into()]),
        predicted: None,
        horizon_s: 180.0,
    };
    let obstacle = Obstacle {
        id: "wreck".into(),
        kind: ObstacleKind::Hard,
        centre: [500.0, 500.0, 200.0],
        radius_m: 30.0,
        inflation_m: 10.0,
    };
    let submission = br#"{"version":1,"scenario_toml":"name = \"x\"\n","mission":"m1","time_scale":10.0,"telemetry_hz":2.0,"iterations":50,"seed":7,"in_process":false}"#.to_vec();
    vec![
        Target {
            name: "bincode AgentToCoordinator",
            seeds: vec![
                bincode(AgentToCoordinator::Joined {
                    mission: "m1".into(),
                    vehicle: "auv1".into(),
                }),
                bincode(AgentToCoordinator::Elites {
                    mission: "m1".into(),
                    vehicle: "auv1".into(),
                    round: 3,
                    iteration: 30,
                    evaluations: 9000,
                    particles: vec![WireChromosome {
                        x: vec![1.0, 2.0],
                        v: vec![0.5, 0.25],
                    }],
                }),
            ],
            versioned: true,
            decode: |b| decode::<AgentToCoordinator>(b).is_ok(),
        },
        Target {
            name: "bincode CoordinatorToAgent",
            seeds: vec![
                bincode(CoordinatorToAgent::Hold {
                    mission: "m1".into(),
                    vehicle: "auv1".into(),
                    reason: "no replan in time".into(),
                }),
                bincode(CoordinatorToAgent::Update {
                    mission: "m1".into(),
                    vehicle: "auv1".into(),
                    revision: 4,
                    trajectory: trajectory.clone(),
                }),
                bincode(CoordinatorToAgent::Execute {
                    mission: "m1".into(),
                    vehicle: "auv1".into(),
                    scenario_toml: "name = \"x\"\n".into(),
                    trajectory,
                    epoch_unix_ms: 1_700_000_000_000,
                    time_scale: 40.0,
                    telemetry_hz: 2.0,
                    seed: 1,
                }),
            ],
            versioned: true,
            decode: |b| decode::<CoordinatorToAgent>(b).is_ok(),
        },
        Target {
            name: "JSON Telemetry",
            seeds: vec![encode_json(&telemetry).unwrap_or_default()],
            versioned: false,
            decode: |b| decode_json::<Telemetry>(b).is_ok(),
        },
        Target {
            name: "JSON Obstacle",
            seeds: vec![encode_json(&obstacle).unwrap_or_default()],
            versioned: false,
            decode: |b| decode_json::<Obstacle>(b).is_ok(),
        },
        Target {
            name: "JSON FleetStatus",
            seeds: vec![encode_json(&status).unwrap_or_default()],
            versioned: false,
            decode: |b| decode_json::<FleetStatus>(b).is_ok(),
        },
        Target {
            name: "JSON Submission",
            seeds: vec![submission],
            versioned: false,
            decode: |b| decode_json::<Submission>(b).is_ok(),
        },
    ]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let inputs: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let seed: u64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(1);
    let mut panicked = 0usize;
    println!("{inputs} inputs per decoder, seed {seed}");
    for t in targets() {
        if t.seeds.iter().any(|s| !(t.decode)(s)) {
            eprintln!("{}: a seed encoding does not decode", t.name);
            std::process::exit(1);
        }
        let mut rng = Rng(seed);
        let mut buf = Vec::with_capacity(1024);
        let (mut ok, mut panics) = (0usize, 0usize);
        let start = Instant::now();
        for _ in 0..inputs {
            input(&t, &mut rng, &mut buf);
            match catch_unwind(AssertUnwindSafe(|| (t.decode)(&buf))) {
                Ok(true) => ok += 1,
                Ok(false) => {}
                Err(_) => {
                    panics += 1;
                    eprintln!("{}: panicked on {:02x?}", t.name, buf);
                }
            }
        }
        let secs = start.elapsed().as_secs_f64();
        println!(
            "{:<28} {:>10.0} inputs/s  {:>8} decoded  {:>8} errors  {} panics  ({secs:.2} s)",
            t.name,
            inputs as f64 / secs,
            ok,
            inputs - ok - panics,
            panics
        );
        panicked += panics;
    }
    if panicked > 0 {
        eprintln!("{panicked} inputs panicked a decoder");
        std::process::exit(1);
    }
}
