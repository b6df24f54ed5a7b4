//! Round trip of one elite exchange over Zenoh on loopback, and the bytes a scenario-3 exchange
//! puts on the wire. An "agent" (client session) sends the Elites message of one agent of
//! scenario 3 (10 chromosomes); the "coordinator" (router session) decodes it and answers with
//! that agent's Migrants (10 chromosomes), which the agent decodes. The leader's own compute is
//! left out: this is the cost the network adds to every round.
//!
//! `cargo bench -p shoal-coordinator --bench exchange` (prints median, p99 and sizes).

use std::path::Path;
use std::time::{Duration, Instant};

use rand::rngs::StdRng;
use rand::SeedableRng;
use shoal_common::cost::FleetModel;
use shoal_common::distributed::Context;
use shoal_common::scenario::Scenario;
use shoal_common::swarm::Problem;
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::{codec, session, topics, Envelope, WireChromosome, WireContext};
use zenoh::qos::CongestionControl;
use zenoh::Wait;

const ROUNDS: usize = 2000;
const WARMUP: usize = 100;

fn main() -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/amp-pso-3.toml");
    let scenario = Scenario::load(&path)?;
    let model = FleetModel::new(&scenario);
    let per_agent = scenario.optimizer.distributed.agent_populations;
    let mut rng = StdRng::seed_from_u64(1);
    let x = model.sample(&mut rng);
    let chromosome = |i: usize| WireChromosome {
        x: x[model.layout.chromosome(i)].to_vec(),
        v: x[model.layout.chromosome(i)]
            .iter()
            .map(|g| g * 0.01)
            .collect(),
    };
    let elites = codec::encode(&Envelope::new(AgentToCoordinator::Elites {
        mission: "bench".into(),
        vehicle: "auv1".into(),
        round: 7,
        iteration: 8,
        evaluations: 4000,
        particles: vec![chromosome(0); per_agent],
    }))?;
    let migrants = codec::encode(&Envelope::new(CoordinatorToAgent::Migrants {
        mission: "bench".into(),
        vehicle: "auv1".into(),
        round: 7,
        context_round: 5,
        particles: vec![chromosome(0); per_agent],
    }))?;
    let ids: Vec<&str> = scenario.vehicles.iter().map(|v| v.id.as_str()).collect();
    let e = model.evaluate(&x);
    let context = codec::encode(&Envelope::new(CoordinatorToAgent::Context {
        mission: "bench".into(),
        context: WireContext::new(&Context::of(5, &e), &ids),
    }))?;

    let port = std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let router = zenoh::open(session::router_config(
        std::slice::from_ref(&endpoint),
        &[],
        &Default::default(),
    )?)
    .wait()?;
    let client = zenoh::open(session::client_config(
        &[endpoint],
        false,
        &Default::default(),
    )?)
    .wait()?;
    let up = topics::to_coordinator("bench", "auv1")?;
    let down = topics::to_agent("bench", "auv1")?;
    let inbox = router.declare_subscriber(up.as_str()).wait()?;
    let agent_inbox = client.declare_subscriber(down.as_str()).wait()?;
    std::thread::sleep(Duration::from_millis(500)); // let the declarations settle
    let responder = {
        let router = router.clone();
        let down = down.clone();
        let migrants = migrants.clone();
        std::thread::spawn(move || -> Result<(), String> {
            for _ in 0..ROUNDS + WARMUP {
                let sample = inbox.recv().map_err(|e| e.to_string())?;
                codec::decode::<AgentToCoordinator>(&sample.payload().to_bytes())
                    .map_err(|e| e.to_string())?;
                router
                    .put(down.as_str(), migrants.clone())
                    .congestion_control(CongestionControl::Block)
                    .wait()
                    .map_err(|e| e.to_string())?;
            }
            Ok(())
        })
    };
    let mut rtts = Vec::with_capacity(ROUNDS);
    for k in 0..ROUNDS + WARMUP {
        let started = Instant::now();
        client
            .put(up.as_str(), elites.clone())
            .congestion_control(CongestionControl::Block)
            .wait()?;
        let reply = agent_inbox
            .recv_timeout(Duration::from_secs(5))?
            .ok_or("no migrants within 5 s")?;
        codec::decode::<CoordinatorToAgent>(&reply.payload().to_bytes())?;
        if k >= WARMUP {
            rtts.push(started.elapsed().as_secs_f64() * 1e6);
        }
    }
    responder.join().map_err(|_| "responder panicked")??;
    rtts.sort_by(f64::total_cmp);
    let at = |q: f64| rtts[((rtts.len() - 1) as f64 * q).round() as usize];
    let vehicles = scenario.vehicles.len();
    let every = scenario.optimizer.distributed.context_every as f64;
    let per_round =
        vehicles * (elites.len() + migrants.len()) + (context.len() as f64 / every) as usize;
    println!("elite exchange round trip on loopback ({ROUNDS} rounds after {WARMUP} warm-up):");
    println!(
        "  median {:.0} µs, p99 {:.0} µs, min {:.0} µs, max {:.0} µs",
        at(0.5),
        at(0.99),
        rtts[0],
        rtts[rtts.len() - 1]
    );
    println!(
        "bytes: elites {} B and migrants {} B per agent per round ({per_agent} chromosomes of {} genes), context {} B",
        elites.len(),
        migrants.len(),
        model.layout.chromosome_len(),
        context.len()
    );
    println!(
        "  scenario 3 ({vehicles} agents, context every {every} rounds): {per_round} B per exchange round, payload only"
    );
    client.close().wait()?;
    router.close().wait()?;
    Ok(())
}
