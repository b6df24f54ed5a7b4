//! Round trip of one elite exchange over Zenoh on loopback, and the bytes a scenario-3 exchange
//! puts on the wire. An "agent" (client session) sends the Elites message of one agent of
//! scenario 3 (10 chromosomes); the "coordinator" (router session) decodes it and answers with
//! that agent's Migrants (10 chromosomes), which the agent decodes. The leader's own compute is
//! left out: this is the cost the network adds to every round.
//!
//! The same exchange runs over plain TCP and over mutual TLS (certificates from `keys`, the
//! access control of a secured coordinator), alternating, so the two are measured side by side.
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
use shoal_common::wire::security::Security;
use shoal_common::wire::{codec, session, topics, Envelope, WireChromosome, WireContext};
use shoal_coordinator::commands::keys::{self, KeysArgs};
use zenoh::qos::CongestionControl;
use zenoh::Wait;

const ROUNDS: usize = 2000;
const WARMUP: usize = 100;
/// Alternating passes per transport, so both see the same machine load.
const PASSES: usize = 3;

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

    let keys_dir = tempfile::tempdir()?;
    let (coordinator, agent) = mtls(keys_dir.path())?;
    let plain = Security::default();
    let (mut tcp, mut tls) = (Vec::new(), Vec::new());
    for _ in 0..PASSES {
        tcp.extend(round_trips("tcp", &plain, &plain, &elites, &migrants)?);
        tls.extend(round_trips(
            "tls",
            &coordinator,
            &agent,
            &elites,
            &migrants,
        )?);
    }
    let vehicles = scenario.vehicles.len();
    let every = scenario.optimizer.distributed.context_every as f64;
    let per_round =
        vehicles * (elites.len() + migrants.len()) + (context.len() as f64 / every) as usize;
    println!(
        "elite exchange round trip on loopback ({ROUNDS} rounds after {WARMUP} warm-up, \
         plain TCP and mutual TLS alternating {PASSES} times):"
    );
    for (name, rtts) in [("tcp", &mut tcp), ("mtls", &mut tls)] {
        rtts.sort_by(f64::total_cmp);
        let at = |q: f64| rtts[((rtts.len() - 1) as f64 * q).round() as usize];
        println!(
            "  {name:<4}: median {:.0} µs, p99 {:.0} µs, min {:.0} µs, max {:.0} µs",
            at(0.5),
            at(0.99),
            rtts[0],
            rtts[rtts.len() - 1]
        );
    }
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
    Ok(())
}

/// Round trips, µs, between a router and a client with these settings on a free loopback port.
fn round_trips(
    protocol: &str,
    router_security: &Security,
    client_security: &Security,
    elites: &[u8],
    migrants: &[u8],
) -> Result<Vec<f64>, Box<dyn std::error::Error + Send + Sync>> {
    let port = std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port();
    let endpoint = format!("{protocol}/127.0.0.1:{port}");
    let router = zenoh::open(session::router_config(
        std::slice::from_ref(&endpoint),
        &[],
        router_security,
    )?)
    .wait()?;
    let client =
        zenoh::open(session::client_config(&[endpoint], false, client_security)?).wait()?;
    let up = topics::to_coordinator("bench", "auv1")?;
    let down = topics::to_agent("bench", "auv1")?;
    let inbox = router.declare_subscriber(up.as_str()).wait()?;
    let agent_inbox = client.declare_subscriber(down.as_str()).wait()?;
    std::thread::sleep(Duration::from_millis(500)); // let the declarations settle
    let responder = {
        let router = router.clone();
        let down = down.clone();
        let migrants = migrants.to_vec();
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
            .put(up.as_str(), elites.to_vec())
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
    client.close().wait()?;
    router.close().wait()?;
    Ok(rtts)
}

/// A coordinator's and auv1's mutual-TLS settings, from certificates `keys` makes in `dir`.
fn mtls(dir: &Path) -> Result<(Security, Security), Box<dyn std::error::Error + Send + Sync>> {
    let args = KeysArgs {
        out: dir.to_path_buf(),
        vehicles: vec!["auv1".into()],
        scenario: None,
        operators: vec![],
        coordinator_hosts: vec!["127.0.0.1".into()],
        path_in_config: None,
        days: 1,
    };
    keys::command(&args).map_err(|e| e.to_string())?;
    let member = |name: &str| Security {
        config_file: Some(dir.join(format!("{name}.json5"))),
        ..Security::default()
    };
    Ok((member("coordinator"), member("auv1")))
}
