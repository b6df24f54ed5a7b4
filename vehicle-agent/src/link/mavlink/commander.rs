//! The commander thread: every exchange with the vehicle (mission and geofence uploads,
//! COMMAND_LONG with its COMMAND_ACK, the hold ladder and its fallback) runs here, beside the
//! agent's telemetry loop, never in it. Each finished command comes back as a [`Done`]; a
//! newer command makes an exchange in progress give way, and the old one comes back given up,
//! so that every command the agent gave is answered.

use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::time::{Duration, Instant};

use mavlink::dialects::common::{self as mav, MavCmd, MavMessage as M, MavMissionType};
use mavlink::{MavConnection, MavHeader};
use shoal_common::execution::{CommandState, VehicleCommand, VehicleStatus};
use shoal_common::scenario::{Bounds, Obstacle};
use shoal_common::trajectory::Trajectory;

use super::super::types::{CommandSerial, LinkError, LinkOutcome, MavlinkSettings};
use super::items::{self, Items, Profile};
use super::reader::{Conn, Shared, READ_TICK};
use shoal_common::geo::GeoOrigin;

/// How long to wait for a heartbeat that names the autopilot before a first upload.
const HEARTBEAT_WAIT: Duration = Duration::from_secs(3);
/// How long each hold step waits for its COMMAND_ACK: short, so that a refused or unanswered
/// hold is known (and reported) within a second, two tries included.
pub const HOLD_WAIT: Duration = Duration::from_millis(300);
/// Tries of each hold step.
const HOLD_TRIES: u32 = 2;

/// A command for the vehicle.
pub enum Job {
    /// Upload the legs of `plan` ending after mission time `after_t` and start them.
    Upload {
        /// The vehicle's timed plan.
        plan: Trajectory,
        /// Only the legs ending after this mission time go up (`None`: the whole plan).
        after_t: Option<f64>,
    },
    /// Hold (or stop) where it is.
    Hold(VehicleCommand),
}

impl Job {
    /// The command the agent gave.
    fn command(&self) -> VehicleCommand {
        match self {
            Job::Upload { .. } => VehicleCommand::Upload,
            Job::Hold(command) => *command,
        }
    }
}

/// What a finished command changes in the link's picture of the vehicle.
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    /// Nothing (a failure, or a step on the way).
    None,
    /// Under way on a new mission: its last item, and where it ends (scenario frame).
    Underway {
        /// Sequence number of the mission's last item.
        last_item: u16,
        /// Where the mission ends, scenario frame.
        goal: [f64; 3],
    },
    /// Held still, as the status says (Holding or Stopped).
    Still(VehicleStatus),
}

/// A command's outcome, and its effect.
pub struct Done {
    /// What the agent reports.
    pub outcome: LinkOutcome,
    /// What the link now believes.
    pub effect: Effect,
}

/// A job a newer one superseded before it was answered (the caller answers it, given up).
struct Superseded;

/// Why an exchange ended early.
enum Abort {
    /// A newer command came: this one gives way.
    Superseded,
    /// The vehicle refused, did not answer, or the link failed.
    Failed(LinkError),
}

impl From<LinkError> for Abort {
    fn from(e: LinkError) -> Abort {
        Abort::Failed(e)
    }
}

/// Where the geofence comes from: the scenario's bounds and obstacles.
#[derive(Debug, Clone)]
pub struct FenceSource {
    /// The box every waypoint stays in.
    pub bounds: Bounds,
    /// The scenario's obstacles (hard ones become exclusion circles).
    pub obstacles: Vec<Obstacle>,
}

/// The commander's side of the link.
pub struct Commander {
    /// The vehicle's MAVLink connection, shared with the telemetry reader.
    pub conn: Arc<Conn>,
    /// Our system and component ids on the link.
    pub header: MavHeader,
    /// The replies the reader passes on (acks, mission requests).
    pub replies: Receiver<M>,
    /// What the reader knows of the vehicle (autopilot, position, mission progress).
    pub shared: Arc<Shared>,
    /// Timeouts and tries of the exchanges.
    pub settings: MavlinkSettings,
    /// The scenario's origin: plans go up as latitude, longitude and altitude.
    pub origin: GeoOrigin,
    /// Where each finished command is reported.
    pub done: Sender<Done>,
    /// The geofence to upload with each mission, if any.
    pub fence: Option<FenceSource>,
    /// Whether the vehicle took a geofence (`None` before the first try; `Some(false)`: it
    /// does not, and none is sent again).
    pub fence_taken: Option<bool>,
    /// The vehicle's autopilot family, once known.
    pub profile: Option<Profile>,
    /// The scenario's surface, AMSL metres (an AUV's), where an ArduPilot home is taken to be
    /// until the vehicle's own position says.
    pub surface_amsl: Option<f64>,
}

impl Commander {
    /// Runs jobs until the link is dropped.
    pub fn run(mut self, jobs: &Receiver<(u64, Job)>) {
        while !self.shared.stop.load(Ordering::Relaxed) {
            match jobs.recv_timeout(READ_TICK) {
                Ok((generation, job)) => {
                    let command = job.command();
                    let answered = if self.shared.superseded(generation) {
                        Err(Superseded)
                    } else {
                        match job {
                            Job::Upload { plan, after_t } => {
                                self.upload(generation, &plan, after_t)
                            }
                            Job::Hold(command) => self.hold(generation, command),
                        }
                    };
                    if answered.is_err() {
                        self.give_way(generation, command);
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
    }

    /// Answers a command a newer one superseded before the vehicle confirmed it: given up.
    fn give_way(&self, serial: CommandSerial, command: VehicleCommand) {
        let why = "superseded by a newer command before the vehicle confirmed it".to_string();
        self.report(serial, command, CommandState::GaveUp, why, Effect::None)
    }

    fn report(
        &self,
        serial: CommandSerial,
        command: VehicleCommand,
        state: CommandState,
        detail: String,
        effect: Effect,
    ) {
        match state {
            CommandState::Confirmed => tracing::info!("mavlink: {}: {detail}", command.name()),
            _ => tracing::warn!("mavlink: {} {state:?}: {detail}", command.name()),
        }
        let outcome = LinkOutcome {
            serial,
            command,
            state,
            detail,
        };
        let _ = self.done.send(Done { outcome, effect }); // fails only once the link is gone
    }

    /// The vehicle's autopilot family: fixed by the settings, else from its HEARTBEAT, waited
    /// for up to `wait` (generic if none comes).
    fn profile(&mut self, wait: Duration) -> Profile {
        if let Some(p) = Profile::chosen(self.settings.autopilot).or(self.profile) {
            return p;
        }
        let deadline = Instant::now() + wait;
        loop {
            if let Some((autopilot, vehicle)) = self.shared.latest().autopilot {
                let p = Profile::from_heartbeat(autopilot, vehicle);
                tracing::info!("mavlink: the vehicle is {autopilot:?} ({vehicle:?}): {p:?}");
                self.profile = Some(p);
                return p;
            }
            if Instant::now() >= deadline {
                return Profile::Generic;
            }
            std::thread::sleep(READ_TICK);
        }
    }

    /// The altitude of home, AMSL metres, for relative frames: the vehicle's own (its
    /// GLOBAL_POSITION_INT carries both its AMSL and its above-home altitude), else the
    /// scenario's surface, else sea level.
    fn home_amsl(&self) -> f64 {
        let latest = self.shared.latest();
        let own = latest
            .global
            .as_ref()
            .map(|g| f64::from(g.alt - g.relative_alt) / 1e3);
        own.or(self.surface_amsl).unwrap_or(0.0)
    }

    fn target(&self) -> (u8, u8) {
        (self.settings.target_system, self.settings.target_component)
    }

    /// Whether a reply's target fields name us (0 = broadcast).
    fn for_us(&self, system: u8, component: u8) -> bool {
        (system == 0 || system == self.settings.system_id)
            && (component == 0 || component == self.settings.component_id)
    }

    fn send(&self, msg: &M) -> Result<(), LinkError> {
        let io = |e| LinkError::Io(format!("{}: {e}", self.settings.address));
        self.conn.send(&self.header, msg).map(drop).map_err(io)
    }

    /// The next reply before `deadline` (`None` then), giving way to a newer command.
    fn reply(&self, deadline: Instant, generation: u64) -> Result<Option<M>, Abort> {
        loop {
            if self.shared.superseded(generation) {
                return Err(Abort::Superseded);
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(None);
            }
            match self.replies.recv_timeout(left.min(READ_TICK)) {
                Ok(msg) => return Ok(Some(msg)),
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(LinkError::Io("reader ended".into()).into())
                }
            }
        }
    }

    /// Drops replies left over from earlier exchanges.
    fn drain(&self) {
        while self.replies.try_recv().is_ok() {
            self.shared.skip();
        }
    }

    /// Sends COMMAND_LONG `command` and waits `wait` for its COMMAND_ACK, `tries` times in all
    /// (`confirmation` counts the resends).
    fn command(
        &self,
        command: MavCmd,
        params: [f32; 7],
        (tries, wait): (u32, Duration),
        generation: u64,
    ) -> Result<(), Abort> {
        self.drain();
        let mut msg = mav::COMMAND_LONG_DATA::default();
        let [p1, p2, p3, p4, p5, p6, p7] = params;
        (msg.command, msg.param1, msg.param2, msg.param3) = (command, p1, p2, p3);
        (msg.param4, msg.param5, msg.param6, msg.param7) = (p4, p5, p6, p7);
        (msg.target_system, msg.target_component) = self.target();
        for attempt in 0..tries.max(1) {
            msg.confirmation = attempt.min(255) as u8;
            self.send(&M::COMMAND_LONG(msg.clone()))?;
            let deadline = Instant::now() + wait;
            while let Some(reply) = self.reply(deadline, generation)? {
                match reply {
                    M::COMMAND_ACK(a) if a.command == command => match a.result {
                        mav::MavResult::MAV_RESULT_ACCEPTED => return Ok(()),
                        mav::MavResult::MAV_RESULT_IN_PROGRESS => {}
                        r => return Err(LinkError::Refused(format!("{r:?}")).into()),
                    },
                    _ => self.shared.skip(),
                }
            }
        }
        let waited = wait * tries.max(1);
        Err(LinkError::Timeout(format!("no COMMAND_ACK in {waited:?} ({tries} tries)")).into())
    }

    /// The upload exchange for `kind`: MISSION_COUNT, a MISSION_ITEM_INT per request, then
    /// MISSION_ACK. Without a reply in `wait` the last message goes again, `tries` times in all.
    fn send_items(
        &self,
        items: &[mav::MISSION_ITEM_INT_DATA],
        kind: MavMissionType,
        (tries, wait): (u32, Duration),
        generation: u64,
    ) -> Result<(), Abort> {
        let n = items.len();
        let count =
            u16::try_from(n).map_err(|_| LinkError::Refused(format!("{n} items: too many")))?;
        self.drain();
        let mut first = mav::MISSION_COUNT_DATA::default();
        (first.count, first.mission_type) = (count, kind);
        (first.target_system, first.target_component) = self.target();
        let mut last = M::MISSION_COUNT(first);
        let (mut waiting, mut sent_all, mut tried) = ("MISSION_REQUEST 0".to_string(), false, 1);
        self.send(&last)?;
        let mut deadline = Instant::now() + wait;
        loop {
            let Some(reply) = self.reply(deadline, generation)? else {
                if tried >= tries {
                    let why = format!("no {waiting} ({tried} tries of {wait:?})");
                    return Err(LinkError::Timeout(why).into());
                }
                tried += 1;
                self.send(&last)?;
                deadline = Instant::now() + wait;
                continue;
            };
            #[allow(deprecated)] // MISSION_REQUEST: older vehicles still send it
            let request = match &reply {
                M::MISSION_REQUEST_INT(r) if r.mission_type == kind => {
                    Some((r.seq, r.target_system, r.target_component))
                }
                M::MISSION_REQUEST(r) if r.mission_type == kind => {
                    Some((r.seq, r.target_system, r.target_component))
                }
                _ => None,
            };
            match (request, reply) {
                (Some((seq, s, c)), _) if self.for_us(s, c) && seq < count => {
                    last = M::MISSION_ITEM_INT(items[usize::from(seq)].clone());
                    self.send(&last)?;
                    sent_all |= seq + 1 == count;
                    waiting = match seq + 1 == count {
                        true => "MISSION_ACK".to_string(),
                        false => format!("MISSION_REQUEST {}", seq + 1),
                    };
                    (tried, deadline) = (1, Instant::now() + wait);
                }
                (_, M::MISSION_ACK(a))
                    if self.for_us(a.target_system, a.target_component)
                        && a.mission_type == kind =>
                {
                    match a.mavtype {
                        mav::MavMissionResult::MAV_MISSION_ACCEPTED if sent_all => return Ok(()),
                        mav::MavMissionResult::MAV_MISSION_ACCEPTED => self.shared.skip(), // stale
                        r => return Err(LinkError::Refused(format!("{r:?}")).into()),
                    }
                }
                _ => self.shared.skip(),
            }
        }
    }

    /// The exchange budget of uploads: the settings' wait and resends.
    fn upload_budget(&self) -> (u32, Duration) {
        (self.settings.retries + 1, self.settings.timeout)
    }

    /// Uploads `items` as the mission and starts it from our first item.
    fn send_mission(&self, items: &Items, generation: u64) -> Result<String, Abort> {
        let mission = MavMissionType::MAV_MISSION_TYPE_MISSION;
        self.send_items(&items.items, mission, self.upload_budget(), generation)?;
        let run = [
            f32::from(items.first),
            f32::from(items.last()),
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ];
        let n = items.items.len();
        // A vehicle may refuse to start (e.g. not armed) yet start later by itself: reported.
        let budget = (2, self.settings.timeout);
        Ok(
            match self.command(MavCmd::MAV_CMD_MISSION_START, run, budget, generation) {
                Ok(()) => format!("{n} items accepted, MISSION_START acknowledged"),
                Err(Abort::Superseded) => return Err(Abort::Superseded),
                Err(Abort::Failed(e)) => format!("{n} items accepted; MISSION_START: {e}"),
            },
        )
    }

    /// Uploads the geofence of `plan` unless the vehicle has shown it takes none; a refusal is
    /// no failure of the mission (the fence is a safety net).
    fn send_fence(&mut self, plan: &Trajectory, generation: u64) -> Result<(), Abort> {
        let Some(source) = self
            .fence
            .as_ref()
            .filter(|_| self.fence_taken != Some(false))
        else {
            return Ok(());
        };
        let target = self.target();
        let items = items::fence_items(
            &source.bounds,
            &source.obstacles,
            plan,
            &self.origin,
            target,
        );
        let fence = MavMissionType::MAV_MISSION_TYPE_FENCE;
        match self.send_items(&items, fence, (1, self.settings.timeout), generation) {
            Ok(()) => {
                tracing::info!("mavlink: geofence of {} items accepted", items.len());
                self.fence_taken = Some(true);
            }
            Err(Abort::Failed(e)) => {
                tracing::info!("mavlink: the vehicle takes no geofence ({e}); none sent again");
                self.fence_taken = Some(false);
            }
            Err(Abort::Superseded) => return Err(Abort::Superseded),
        }
        Ok(())
    }

    /// Uploads `plan` (its legs after `after_t`) with the geofence and starts it, reporting
    /// the outcome; `Err` when a newer job superseded it, which [`Commander::run`] answers.
    fn upload(
        &mut self,
        generation: u64,
        plan: &Trajectory,
        after_t: Option<f64>,
    ) -> Result<(), Superseded> {
        let profile = self.profile(HEARTBEAT_WAIT);
        let frame = (profile, self.home_amsl());
        let items = items::mission_items(plan, &self.origin, after_t, self.target(), frame);
        let sent = self
            .send_fence(plan, generation)
            .and_then(|()| self.send_mission(&items, generation));
        let goal = plan.points.last().map_or([0.0; 3], |p| (*p).into());
        let upload = VehicleCommand::Upload;
        match sent {
            Ok(detail) => {
                let effect = Effect::Underway {
                    last_item: items.last(),
                    goal,
                };
                self.report(generation, upload, CommandState::Confirmed, detail, effect)
            }
            Err(Abort::Failed(e)) => {
                let why = format!("mission upload: {e}");
                self.report(generation, upload, CommandState::GaveUp, why, Effect::None)
            }
            Err(Abort::Superseded) => return Err(Superseded),
        }
        Ok(())
    }

    /// Holds (or stops) the vehicle: each of the profile's hold steps in turn, then the
    /// fallback mission that ends where the vehicle is. Every failure is reported at once;
    /// `Err` when a newer job superseded it, which [`Commander::run`] answers.
    fn hold(&mut self, generation: u64, command: VehicleCommand) -> Result<(), Superseded> {
        let status = match command {
            VehicleCommand::Stop => VehicleStatus::Stopped,
            _ => VehicleStatus::Holding,
        };
        let profile = self.profile(Duration::ZERO);
        let mut failures = Vec::new();
        let steps = profile.hold_steps();
        for (k, step) in steps.iter().enumerate() {
            match self.command(
                step.command,
                step.params,
                (HOLD_TRIES, HOLD_WAIT),
                generation,
            ) {
                Ok(()) => {
                    let how = format!("{} acknowledged", step.label);
                    let still = Effect::Still(status);
                    self.report(generation, command, CommandState::Confirmed, how, still);
                    return Ok(());
                }
                Err(Abort::Superseded) => return Err(Superseded),
                Err(Abort::Failed(e)) => {
                    failures.push(format!("{}: {e}", step.label));
                    let next = steps
                        .get(k + 1)
                        .map_or("a mission ending where it is", |s| &s.label);
                    let why = format!("{}; trying {next}", failures.join("; "));
                    self.report(generation, command, CommandState::Failed, why, Effect::None);
                }
            }
        }
        let here = self.shared.latest().geodetic(&self.origin);
        let Some(here) = here else {
            failures.push("no position to hold at".into());
            let why = failures.join("; ");
            self.report(generation, command, CommandState::GaveUp, why, Effect::None);
            return Ok(());
        };
        let items = items::fallback_items(here, self.target(), (profile, self.home_amsl()));
        match self.send_mission(&items, generation) {
            Ok(detail) => {
                let [lat, lon, alt] = here;
                let how = format!(
                    "by a mission ending where it is ({lat:.7}, {lon:.7}, {alt:.1} m): {detail}; after {}",
                    failures.join("; ")
                );
                self.report(
                    generation,
                    command,
                    CommandState::Confirmed,
                    how,
                    Effect::Still(status),
                )
            }
            Err(Abort::Superseded) => return Err(Superseded),
            Err(Abort::Failed(e)) => {
                failures.push(format!("fallback mission: {e}"));
                self.report(
                    generation,
                    command,
                    CommandState::GaveUp,
                    failures.join("; "),
                    Effect::None,
                )
            }
        }
        Ok(())
    }
}
