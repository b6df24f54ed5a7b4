//! What a vehicle made of the commands its agent gave it (a hold, a stop, a new plan), read
//! from the [`CommandReport`] every telemetry report carries: a refusal or silence becomes an
//! event at once, so the coordinator's picture never says "holding" of a vehicle that is not.

use shoal_common::execution::{CommandReport, CommandState};

/// The event (kind, detail) when vehicle `id`'s command report went from `before` to `now`:
/// `hold_failed` / `stop_failed` / `upload_failed` when the vehicle refused or did not answer
/// (the detail names the fallback tried, or says it goes on as before), `…_confirmed` when it
/// took the command after such a failure. Nothing for a report that did not change, or for a
/// plain confirmation.
pub fn change(
    id: &str,
    before: Option<&CommandReport>,
    now: Option<&CommandReport>,
) -> Option<(String, String)> {
    let now = now?;
    let same = |b: &&CommandReport| b.command == now.command && b.given_s == now.given_s;
    let before = before.filter(same);
    if before.is_some_and(|b| b.state == now.state) {
        return None;
    }
    let failed_before =
        before.is_some_and(|b| matches!(b.state, CommandState::Failed | CommandState::GaveUp));
    let (name, at, detail) = (now.command.name(), now.given_s, &now.detail);
    let given = format!("the {name} given at t = {at:.1} s");
    match now.state {
        CommandState::Failed => Some((
            format!("{name}_failed"),
            format!("{id} did not take {given}: {detail}"),
        )),
        CommandState::GaveUp => Some((
            format!("{name}_failed"),
            format!("{id} did not take {given}, nor any fallback: it goes on as before ({detail})"),
        )),
        CommandState::Confirmed if failed_before => Some((
            format!("{name}_confirmed"),
            format!("{id} confirmed {given} {detail}"),
        )),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::execution::VehicleCommand;

    fn report(
        command: VehicleCommand,
        state: CommandState,
        detail: &str,
        at: f64,
    ) -> CommandReport {
        CommandReport {
            command,
            state,
            detail: detail.into(),
            given_s: at,
        }
    }

    #[test]
    fn a_refused_hold_is_an_event_once_and_its_fallback_confirmation_another() {
        use CommandState::*;
        use VehicleCommand::Hold;
        let pending = report(Hold, Pending, "sent", 120.0);
        let failed = report(
            Hold,
            Failed,
            "DENIED; trying a mission ending where it is",
            120.0,
        );
        let took = report(Hold, Confirmed, "by a mission ending where it is", 120.0);
        assert_eq!(change("auv1", None, Some(&pending)), None);
        let Some((kind, detail)) = change("auv1", Some(&pending), Some(&failed)) else {
            panic!("no event for a refused hold")
        };
        assert_eq!(kind, "hold_failed");
        assert_eq!(
            detail,
            "auv1 did not take the hold given at t = 120.0 s: DENIED; trying a mission ending where it is"
        );
        // The same failure in the next report is no new event.
        assert_eq!(change("auv1", Some(&failed), Some(&failed)), None);
        let Some((kind, _)) = change("auv1", Some(&failed), Some(&took)) else {
            panic!("no event for the fallback taken")
        };
        assert_eq!(kind, "hold_confirmed");
        // A hold confirmed straight away is no event; a new hold's failure is one.
        assert_eq!(change("auv1", Some(&pending), Some(&took)), None);
        let later = report(Hold, GaveUp, "no position to hold at", 300.0);
        let Some((kind, detail)) = change("auv1", Some(&took), Some(&later)) else {
            panic!("no event for a later hold given up")
        };
        assert_eq!(kind, "hold_failed");
        assert!(detail.contains("goes on as before"), "{detail}");
        let stop = report(VehicleCommand::Stop, GaveUp, "no COMMAND_ACK", 400.0);
        let kind = change("auv1", Some(&later), Some(&stop)).map(|(k, _)| k);
        assert_eq!(kind.as_deref(), Some("stop_failed"));
    }
}
