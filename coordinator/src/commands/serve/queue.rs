//! The missions `serve` has accepted and not yet run: bounded ([`limits::MAX_QUEUED_MISSIONS`]),
//! so a flood of submissions is refused with a reason instead of piling up, and each id taken
//! once (a second mission of the same id would overwrite the first one's files).

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Duration;

use shoal_common::limits;

use super::refusal::QueueError;
use super::submission::Submission;

/// Shared by the submission callback (which offers) and the serving loop (which takes).
#[derive(Debug)]
pub struct Queue {
    /// Where mission directories go: an id whose directory exists is taken.
    out: PathBuf,
    /// Waiting missions and the running one.
    state: Mutex<State>,
    /// Signalled when a mission is offered.
    offered: Condvar,
}

/// What the queue holds.
#[derive(Debug, Default)]
struct State {
    /// Accepted, not started, in order.
    waiting: VecDeque<(String, Submission)>,
    /// The mission being run, whose directory may not exist yet.
    running: Option<String>,
}

impl Queue {
    /// An empty queue for missions whose files go under `out`.
    pub fn new(out: PathBuf) -> Queue {
        Queue {
            out,
            state: Mutex::new(State::default()),
            offered: Condvar::new(),
        }
    }

    /// The state; a panic elsewhere while it was held leaves it usable (it is only a list).
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Puts `mission` at the back, or says why not: the queue is full, or the id is waiting,
    /// running or already has a directory under `out`.
    pub fn offer(&self, mission: String, s: Submission) -> Result<(), QueueError> {
        let mut state = self.lock();
        let taken = state.running.as_deref() == Some(mission.as_str())
            || state.waiting.iter().any(|(m, _)| *m == mission)
            || self.out.join(&mission).symlink_metadata().is_ok();
        if taken {
            return Err(QueueError::Taken(mission));
        }
        if state.waiting.len() >= limits::MAX_QUEUED_MISSIONS {
            return Err(QueueError::Full(state.waiting.len()));
        }
        state.waiting.push_back((mission, s));
        self.offered.notify_one();
        Ok(())
    }

    /// The next mission, marked running, or `None` when none came within `wait`.
    pub fn take(&self, wait: Duration) -> Option<(String, Submission)> {
        let mut state = self.lock();
        if state.waiting.is_empty() {
            state = match self.offered.wait_timeout(state, wait) {
                Ok((s, _)) => s,
                Err(p) => p.into_inner().0,
            };
        }
        let next = state.waiting.pop_front()?;
        state.running = Some(next.0.clone());
        Some(next)
    }

    /// The running mission ended.
    pub fn finished(&self) {
        self.lock().running = None;
    }

    /// Empties the queue; the ids of the missions that were waiting, in order.
    pub fn drain(&self) -> Vec<String> {
        self.lock().waiting.drain(..).map(|(m, _)| m).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sub() -> Submission {
        Submission {
            version: 1,
            scenario_toml: String::new(),
            mission: None,
            time_scale: None,
            telemetry_hz: None,
            iterations: None,
            seed: None,
            in_process: false,
        }
    }

    #[test]
    fn the_queue_refuses_the_ninth_waiting_mission_with_a_reason() {
        let q = Queue::new(PathBuf::from("/nonexistent-shoal-out"));
        for i in 0..limits::MAX_QUEUED_MISSIONS {
            assert_eq!(q.offer(format!("m{i}"), sub()), Ok(()));
        }
        assert_eq!(q.offer("m8".into(), sub()), Err(QueueError::Full(8)));
        assert_eq!(
            QueueError::Full(8).to_string(),
            "queue full: 8 missions waiting (try again later)"
        );
        // Taking one makes room for one.
        assert_eq!(q.take(Duration::ZERO).map(|(m, _)| m), Some("m0".into()));
        assert_eq!(q.offer("m8".into(), sub()), Ok(()));
        let left: Vec<String> = (1..=8).map(|i| format!("m{i}")).collect();
        assert_eq!(q.drain(), left);
        assert!(q.take(Duration::ZERO).is_none());
    }

    #[test]
    fn an_id_waiting_running_or_with_a_directory_is_refused() -> std::io::Result<()> {
        let out = tempfile::tempdir()?;
        std::fs::create_dir(out.path().join("done"))?;
        let q = Queue::new(out.path().to_path_buf());
        assert_eq!(q.offer("a".into(), sub()), Ok(()));
        assert_eq!(q.offer("b".into(), sub()), Ok(()));
        assert_eq!(q.take(Duration::ZERO).map(|(m, _)| m), Some("a".into()));
        for taken in ["a", "b", "done"] {
            let e = q
                .offer(taken.into(), sub())
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(e.contains(&format!("{taken:?} is already taken")), "{e}");
        }
        // Once the running mission ends, its id is free only if it left no directory.
        q.finished();
        assert_eq!(q.offer("a".into(), sub()), Ok(()));
        Ok(())
    }
}
