//! Whether a mission's coordinator has left the network.
//!
//! A coordinator declares a liveliness token (`shoal-coordinator/<mission>`); its agents watch
//! it so that a coordinator that exits, crashes or loses its link ends their missions at once
//! instead of after `--idle-timeout`. A single `Delete` of that token is not proof, though:
//! a link that drops and reconnects produces a `Delete` and then a `Put`, and a Zenoh router
//! with access control has been seen to deliver a `Delete` to one client while the token stayed
//! declared (one agent of three abandoned a mission whose coordinator ran on). A vehicle that
//! stops its mission on such a flicker is taken out of the fleet for nothing.
//!
//! So a `Delete` makes the coordinator a suspect. If its token comes back within
//! [`DEPARTURE_GRACE`], the suspicion is dropped. Otherwise the agent asks the network with a
//! liveliness query ([`coordinator_present`]) and takes the coordinator as gone only if no token
//! answers. The query runs on a thread of its own, so the agent's loop (and through it the
//! vehicle's orders) never waits on it.

use std::collections::HashMap;
use std::sync::mpsc::{self, Receiver, Sender};
use std::time::{Duration, Instant};

use shoal_common::wire::topics;
use zenoh::{Session, Wait};

/// How long a coordinator's token may be gone before the agent asks whether it is.
pub const DEPARTURE_GRACE: Duration = Duration::from_secs(2);

/// How long the liveliness query waits for a token to answer.
pub const PRESENCE_QUERY_TIMEOUT: Duration = Duration::from_secs(2);

/// Where a suspected coordinator stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Suspect {
    /// Its token went at this instant and has not come back.
    GoneSince(Instant),
    /// The network is being asked.
    Asking,
}

/// The coordinators suspected of having left, by mission.
#[derive(Debug)]
pub struct CoordinatorWatch {
    grace: Duration,
    suspects: HashMap<String, Suspect>,
}

impl CoordinatorWatch {
    /// A watch that waits `grace` after a token goes before asking.
    pub fn new(grace: Duration) -> CoordinatorWatch {
        CoordinatorWatch {
            grace,
            suspects: HashMap::new(),
        }
    }

    /// `mission`'s coordinator token went at `now` (a question already under way stands).
    pub fn token_gone(&mut self, mission: &str, now: Instant) {
        self.suspects
            .entry(mission.to_string())
            .or_insert(Suspect::GoneSince(now));
    }

    /// `mission`'s coordinator token is declared (again): it has not left.
    pub fn token_back(&mut self, mission: &str) {
        self.suspects.remove(mission);
    }

    /// The missions whose coordinator has been gone for the grace period at `now`: the network
    /// is to be asked about each, once.
    pub fn questions_due(&mut self, now: Instant) -> Vec<String> {
        let mut ask = Vec::new();
        for (mission, s) in &mut self.suspects {
            if let Suspect::GoneSince(t) = *s {
                if now.saturating_duration_since(t) >= self.grace {
                    *s = Suspect::Asking;
                    ask.push(mission.clone());
                }
            }
        }
        ask.sort();
        ask
    }

    /// The network's answer about `mission`'s coordinator: true when it has left (no token
    /// answered and none came back while the question was out).
    pub fn answer(&mut self, mission: &str, present: bool) -> bool {
        if self.suspects.get(mission) != Some(&Suspect::Asking) {
            return false;
        }
        self.suspects.remove(mission);
        !present
    }

    /// Forgets `mission` (it ended).
    pub fn forget(&mut self, mission: &str) {
        self.suspects.remove(mission);
    }
}

/// The watch as the agent's loop drives it: token news in, questions out on threads, departures
/// back.
pub struct Departures {
    watch: CoordinatorWatch,
    /// `(mission, declared)` for every `Put` and `Delete` of a coordinator token.
    tokens: Receiver<(String, bool)>,
    answers_tx: Sender<(String, bool)>,
    answers: Receiver<(String, bool)>,
}

impl Departures {
    /// Watches the token news on `tokens` with the [`DEPARTURE_GRACE`].
    pub fn new(tokens: Receiver<(String, bool)>) -> Departures {
        let (answers_tx, answers) = mpsc::channel();
        Departures {
            watch: CoordinatorWatch::new(DEPARTURE_GRACE),
            tokens,
            answers_tx,
            answers,
        }
    }

    /// The missions, among those `serving` names, whose coordinator has left as of now; never
    /// waits for the network.
    pub fn poll(&mut self, session: &Session, serving: impl Fn(&str) -> bool) -> Vec<String> {
        let now = Instant::now();
        while let Ok((mission, declared)) = self.tokens.try_recv() {
            if declared {
                self.watch.token_back(&mission);
            } else if serving(&mission) {
                self.watch.token_gone(&mission, now);
            }
        }
        for mission in self.watch.questions_due(now) {
            ask(session, mission, self.answers_tx.clone());
        }
        let mut gone = Vec::new();
        while let Ok((mission, present)) = self.answers.try_recv() {
            if self.watch.answer(&mission, present) {
                gone.push(mission);
            } else if present {
                tracing::info!(
                    "mission {mission}: its coordinator's liveliness token went and a query \
                     still finds it; the mission goes on"
                );
            }
        }
        gone
    }

    /// Forgets `mission` (it ended).
    pub fn forget(&mut self, mission: &str) {
        self.watch.forget(mission);
    }
}

/// Whether a liveliness query finds `mission`'s coordinator token within `timeout`.
pub fn coordinator_present(session: &Session, mission: &str, timeout: Duration) -> bool {
    let Ok(key) = topics::coordinator_liveliness(mission) else {
        return false;
    };
    match session
        .liveliness()
        .get(key.as_str())
        .timeout(timeout)
        .wait()
    {
        Ok(replies) => {
            let mut found = false;
            while let Ok(reply) = replies.recv() {
                found |= reply.result().is_ok();
            }
            found
        }
        Err(e) => {
            tracing::warn!("cannot ask whether the coordinator of {mission} is there: {e}");
            false
        }
    }
}

/// Asks on a thread of its own whether `mission`'s coordinator is there; the answer goes to
/// `answers` as `(mission, present)`.
fn ask(session: &Session, mission: String, answers: Sender<(String, bool)>) {
    let session = session.clone();
    std::thread::spawn(move || {
        let present = coordinator_present(&session, &mission, PRESENCE_QUERY_TIMEOUT);
        let _ = answers.send((mission, present));
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    const GRACE: Duration = Duration::from_secs(2);

    #[test]
    fn a_token_that_comes_back_within_the_grace_is_never_asked_about() {
        let mut w = CoordinatorWatch::new(GRACE);
        let t0 = Instant::now();
        w.token_gone("m", t0);
        assert!(w.questions_due(t0 + Duration::from_millis(1999)).is_empty());
        w.token_back("m");
        assert!(w.questions_due(t0 + Duration::from_secs(10)).is_empty());
    }

    #[test]
    fn a_token_gone_for_the_grace_is_asked_about_once_and_only_an_empty_answer_is_a_departure() {
        let mut w = CoordinatorWatch::new(GRACE);
        let t0 = Instant::now();
        w.token_gone("m", t0);
        // A second Delete does not restart the grace.
        w.token_gone("m", t0 + Duration::from_secs(1));
        assert_eq!(w.questions_due(t0 + GRACE), vec!["m".to_string()]);
        assert!(w.questions_due(t0 + GRACE * 5).is_empty(), "asked twice");
        assert!(w.answer("m", false), "no token answered: it left");
        assert!(!w.answer("m", false), "answered twice");

        w.token_gone("n", t0);
        assert_eq!(w.questions_due(t0 + GRACE), vec!["n".to_string()]);
        assert!(!w.answer("n", true), "a token answered: it is there");
        assert!(w.questions_due(t0 + GRACE * 5).is_empty());
    }

    #[test]
    fn a_token_back_while_the_question_is_out_outweighs_an_empty_answer() {
        let mut w = CoordinatorWatch::new(GRACE);
        let t0 = Instant::now();
        w.token_gone("m", t0);
        assert_eq!(w.questions_due(t0 + GRACE), vec!["m".to_string()]);
        w.token_back("m");
        assert!(!w.answer("m", false));
        // A mission that ended is forgotten with its suspicion.
        w.token_gone("k", t0);
        w.forget("k");
        assert!(w.questions_due(t0 + GRACE).is_empty());
        assert!(!w.answer("k", false));
    }

    #[test]
    fn several_missions_are_watched_apart() {
        let mut w = CoordinatorWatch::new(GRACE);
        let t0 = Instant::now();
        w.token_gone("b", t0);
        w.token_gone("a", t0 + Duration::from_secs(1));
        assert_eq!(w.questions_due(t0 + GRACE), vec!["b".to_string()]);
        assert_eq!(w.questions_due(t0 + GRACE * 2), vec!["a".to_string()]);
        assert!(!w.answer("a", true));
        assert!(w.answer("b", false));
    }
}
