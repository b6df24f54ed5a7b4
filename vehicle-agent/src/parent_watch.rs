//! An embedded agent's tie to the coordinator that started it. The coordinator passes its own
//! process id (`--parent-pid`) and the agent leaves when that process is no longer its parent.
//! A coordinator that exits kills its agents itself; one killed by SIGKILL or by the kernel's
//! out-of-memory killer cannot, and its agents would wait for missions from a router that is
//! gone, then join whatever coordinator is started next on that endpoint with the same keys,
//! alongside that coordinator's own agents for the same vehicles.
//!
//! Polled, not Linux's `PR_SET_PDEATHSIG`: that signal needs `unsafe` code in the child before
//! `exec`, and it fires when the *thread* that spawned the child ends, not the process (a
//! coordinator spawning agents from a short-lived thread would kill them at once). A look at
//! the parent every [`POLL`] costs nothing and works on every Unix.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// How often the parent is looked at: an orphaned agent leaves within this plus its own
/// shutdown (at most 100 ms while it waits for a router or for messages).
pub const POLL: Duration = Duration::from_millis(200);

/// The process id of this process's parent (0 where the parent is outside its process
/// namespace), or `None` where the platform has no such notion.
pub fn parent_id() -> Option<u32> {
    #[cfg(unix)]
    return Some(std::os::unix::process::parent_id());
    #[cfg(not(unix))]
    return None;
}

/// Raises `shutdown` once process `parent` is no longer this process's parent, from a thread
/// of its own that ends when `shutdown` is raised by anything else.
pub fn start(parent: u32, vehicle: &str, shutdown: Arc<AtomicBool>) {
    let vehicle = vehicle.to_string();
    let watch = move || {
        while !shutdown.load(Ordering::Relaxed) {
            match parent_id() {
                Some(now) if now != parent => {
                    tracing::warn!(
                        "agent for {vehicle}: process {parent}, which started it, is gone \
                         (parent now {now}); leaving"
                    );
                    shutdown.store(true, Ordering::SeqCst);
                    return;
                }
                Some(_) => std::thread::sleep(POLL),
                None => return,
            }
        }
    };
    if let Err(e) = std::thread::Builder::new()
        .name("parent-watch".into())
        .spawn(watch)
    {
        tracing::warn!("cannot watch the parent process: {e}");
    }
}
