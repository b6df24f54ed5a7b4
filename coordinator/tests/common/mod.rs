//! What the coordinator's integration tests share: agents on threads of this process.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

use shoal_agent::AgentConfig;

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
    let config = AgentConfig {
        once: true,
        idle_timeout: std::time::Duration::from_secs(10),
        ..AgentConfig::new(vehicle, vec![endpoint.into()])
    };
    let flag = Arc::clone(&stop);
    Agent {
        stop,
        handle: std::thread::spawn(move || shoal_agent::run(config, flag)),
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
