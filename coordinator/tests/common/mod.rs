//! What the coordinator's integration tests share: agents on threads of this process.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

use shoal_agent::AgentArgs;

pub type TestResult = Result<(), Box<dyn std::error::Error>>;

/// A loopback endpoint on a port free a moment ago.
pub fn free_endpoint() -> std::io::Result<String> {
    let l = std::net::TcpListener::bind("127.0.0.1:0")?;
    Ok(format!("tcp/127.0.0.1:{}", l.local_addr()?.port()))
}

/// An agent on a thread, with its own stop flag.
pub struct Agent {
    pub stop: Arc<AtomicBool>,
    pub handle: JoinHandle<anyhow::Result<()>>,
}

/// The agent of `vehicle`, connecting to `endpoint`, leaving after its first mission.
pub fn agent(vehicle: &str, endpoint: &str) -> Agent {
    let stop = Arc::new(AtomicBool::new(false));
    let args = AgentArgs {
        vehicle: vehicle.into(),
        connect: vec![endpoint.into()],
        zenoh: Default::default(),
        once: true,
        threads: 1,
        idle_timeout: 10.0,
        health_file: None,
        health_check: false,
        link: shoal_agent::link::LinkKind::Sim,
        position_noise: 1.0,
        mavlink_address: None,
        mavlink_origin: None,
        mavlink_target: None,
        mavlink_autopilot: shoal_agent::link::mavlink::AutopilotChoice::Auto,
        mavlink_no_fence: false,
    };
    let flag = Arc::clone(&stop);
    Agent {
        stop,
        handle: std::thread::spawn(move || shoal_agent::run(args, flag)),
    }
}

/// Stops the agents and waits for them; an agent's error fails the test.
pub fn finish(agents: Vec<Agent>) -> TestResult {
    for a in agents {
        a.stop.store(true, Ordering::Relaxed);
        match a.handle.join() {
            Ok(r) => r?,
            Err(_) => return Err("an agent thread panicked".into()),
        }
    }
    Ok(())
}
