//! Independent MAVLink vehicles for end-to-end tests of the `mavlink` link, run as Python
//! processes that print one JSON object per line:
//!
//! - [`Kind::Mavsdk`]: MAVSDK 4.1 as the autopilot (`tests/python/mavsdk_vehicle.py`);
//! - [`Kind::ArduPilot`]: ArduSub's mission and command handling written with pymavlink
//!   (`tests/python/ardupilot_vehicle.py`).
//!
//! Both move in real time along the mission they are given (`tests/python/vehicle_kinematics.py`).
//! The interpreter comes from [`shoal_interop::python`] (a venv with the pinned packages).
//!
//! A test is a few lines: spawn a vehicle at a plan's start, connect a link to it, upload, then
//! [`follow`] the link's states and read the vehicle's own account ([`Vehicle::wait_for`],
//! [`Vehicle::events`]).

// Each test file that includes this module uses only part of it.
#![allow(dead_code)]

use std::error::Error;
use std::io::{BufRead, BufReader, Read};
use std::net::UdpSocket;
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use serde_json::Value;
use shoal_agent::link::mavlink::{MavlinkLink, Placement};
use shoal_agent::link::{GeoOrigin, LinkOutcome, MavlinkSettings, VehicleLink};
use shoal_common::execution::{VehicleCommand, VehicleState};
use shoal_common::trajectory::Trajectory;

pub type TestResult = Result<(), Box<dyn Error>>;

/// The scenario origin every vehicle test uses.
pub const ORIGIN: GeoOrigin = GeoOrigin::new(43.1, 5.9, 0.0);

/// Which vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// MAVSDK 4.1 (`mavsdk_vehicle.py`).
    Mavsdk,
    /// ArduSub-style, pymavlink (`ardupilot_vehicle.py`).
    ArduPilot,
}

impl Kind {
    fn script(self) -> &'static str {
        match self {
            Kind::Mavsdk => "mavsdk_vehicle.py",
            Kind::ArduPilot => "ardupilot_vehicle.py",
        }
    }
}

/// A free UDP port on loopback (bound, read, released).
pub fn free_port() -> Result<u16, std::io::Error> {
    Ok(UdpSocket::bind("127.0.0.1:0")?.local_addr()?.port())
}

/// `LAT,LON,ALT` of scenario point `p`, for a vehicle's `--home`.
pub fn home_arg(p: [f64; 3]) -> String {
    let [lat, lon, alt] = ORIGIN.to_geodetic(p);
    format!("{lat:.9},{lon:.9},{alt:.3}")
}

/// A vehicle process; killed (and its stderr printed if the test failed) when dropped.
pub struct Vehicle {
    /// The UDP port it listens on.
    pub port: u16,
    /// Every line read so far, in order.
    pub seen: Vec<Value>,
    child: Child,
    /// Closing it ends the vehicle (exit 0).
    stdin: Option<ChildStdin>,
    lines: Receiver<String>,
    stderr: Arc<Mutex<String>>,
}

impl Vehicle {
    /// Starts `kind` on a free port with `args` (after the port), and waits for its `listening`
    /// line.
    pub fn spawn(kind: Kind, args: &[&str]) -> Result<Vehicle, Box<dyn Error>> {
        let py = shoal_interop::python()?;
        let port = free_port()?;
        let script = format!(
            "{}/../tests/python/{}",
            env!("CARGO_MANIFEST_DIR"),
            kind.script()
        );
        let mut child = Command::new(&py)
            .arg(&script)
            .arg(port.to_string())
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("{py} {script}: {e}"))?;
        let (stdout, stdin) = (child.stdout.take(), child.stdin.take());
        let (stderr, log) = (child.stderr.take(), Arc::new(Mutex::new(String::new())));
        let (tx, lines) = mpsc::channel();
        if let Some(out) = stdout {
            std::thread::spawn(move || {
                BufReader::new(out)
                    .lines()
                    .map_while(Result::ok)
                    .try_for_each(|l| tx.send(l))
            });
        }
        if let Some(mut err) = stderr {
            let log = Arc::clone(&log);
            std::thread::spawn(move || {
                let mut text = String::new();
                let _ = err.read_to_string(&mut text); // whatever came before a failure
                log.lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .push_str(&text);
            });
        }
        let mut vehicle = Vehicle {
            port,
            seen: Vec::new(),
            child,
            stdin,
            lines,
            stderr: log,
        };
        vehicle.wait_for("listening", Duration::from_secs(20))?;
        Ok(vehicle)
    }

    /// Link settings for this vehicle: `udpout:` to its port, [`ORIGIN`], replies awaited
    /// `timeout_ms` and resent `retries` times.
    pub fn settings(&self, timeout_ms: u64, retries: u32) -> MavlinkSettings {
        let address = format!("udpout:127.0.0.1:{}", self.port);
        let mut s = MavlinkSettings::new(address, Some(ORIGIN));
        (s.timeout, s.retries) = (Duration::from_millis(timeout_ms), retries);
        s
    }

    /// Reads one line into `seen`, waiting up to `wait`; false when none came.
    fn read(&mut self, wait: Duration) -> Result<bool, String> {
        match self.lines.recv_timeout(wait) {
            Ok(line) => {
                let v = serde_json::from_str(&line).map_err(|e| format!("{line:?}: {e}"))?;
                self.seen.push(v);
                Ok(true)
            }
            Err(RecvTimeoutError::Timeout) => Ok(false),
            Err(RecvTimeoutError::Disconnected) => Err("the vehicle's stdout closed".into()),
        }
    }

    /// Reads whatever lines have arrived, without waiting.
    pub fn poll(&mut self) -> Result<(), String> {
        while self.read(Duration::ZERO)? {}
        Ok(())
    }

    /// The first event named `name` the vehicle printed, waiting up to `within` for it.
    pub fn wait_for(&mut self, name: &str, within: Duration) -> Result<Value, String> {
        self.wait_for_nth(name, 1, within)
    }

    /// The `n`th event named `name` (from 1) the vehicle printed, waiting up to `within`.
    pub fn wait_for_nth(
        &mut self,
        name: &str,
        n: usize,
        within: Duration,
    ) -> Result<Value, String> {
        let deadline = Instant::now() + within;
        loop {
            if let Some(v) = self.events(name).get(n.saturating_sub(1)) {
                return Ok((*v).clone());
            }
            let left = deadline.saturating_duration_since(Instant::now());
            let why = match left.is_zero() {
                true => format!("no {name:?} number {n} within {within:?}"),
                false => match self.read(left.min(Duration::from_millis(50))) {
                    Ok(_) => continue,
                    Err(e) => format!("no {name:?} number {n}: {e}"),
                },
            };
            let tail: Vec<String> = self
                .seen
                .iter()
                .rev()
                .take(8)
                .map(Value::to_string)
                .collect();
            return Err(format!("{why}; last lines, newest first: {tail:#?}"));
        }
    }

    /// Events named `name` read so far.
    pub fn events(&self, name: &str) -> Vec<&Value> {
        self.seen.iter().filter(|v| v["event"] == name).collect()
    }

    /// Closes its stdin, waits for it to exit (5 s) and reads all it printed.
    pub fn finish(mut self) -> Result<(ExitStatus, Vec<Value>), String> {
        drop(self.stdin.take());
        let deadline = Instant::now() + Duration::from_secs(5);
        let status = loop {
            match self.child.try_wait().map_err(|e| e.to_string())? {
                Some(status) => break status,
                None if Instant::now() > deadline => return Err("it did not exit".into()),
                None => std::thread::sleep(Duration::from_millis(20)),
            }
        };
        while let Ok(true) = self.read(Duration::from_millis(200)) {}
        Ok((status, std::mem::take(&mut self.seen)))
    }
}

impl Drop for Vehicle {
    fn drop(&mut self) {
        drop(self.stdin.take());
        let _ = self.child.kill();
        let _ = self.child.wait();
        if std::thread::panicking() {
            let log = self.stderr.lock().unwrap_or_else(PoisonError::into_inner);
            eprintln!("--- vehicle stderr ---\n{log}\n--- vehicle stdout ---");
            self.seen.iter().for_each(|v| eprintln!("{v}"));
        }
    }
}

/// A number field of an event.
pub fn num(event: &Value, key: &str) -> Option<f64> {
    event.get(key).and_then(Value::as_f64)
}

/// Connects a link to `vehicle` (at [`ORIGIN`], no geofence) and waits (5 s) for its first
/// position.
pub fn connect(vehicle: &Vehicle, timeout_ms: u64, retries: u32) -> Result<MavlinkLink, String> {
    connect_placed(vehicle, timeout_ms, retries, Placement::at(ORIGIN))
}

/// [`connect`] for a mission placed as `place` says.
pub fn connect_placed(
    vehicle: &Vehicle,
    timeout_ms: u64,
    retries: u32,
    place: Placement,
) -> Result<MavlinkLink, String> {
    let settings = vehicle.settings(timeout_ms, retries);
    let mut link = MavlinkLink::connect(&settings, place).map_err(|e| e.to_string())?;
    let deadline = Instant::now() + Duration::from_secs(5);
    while link.state(0.0).is_err() {
        if Instant::now() > deadline {
            return Err("no position from the vehicle in 5 s".into());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    Ok(link)
}

/// Polls `link.state(mission time)` every 100 ms, mission time being the seconds since `t0`,
/// until `done` holds (that state included) or `within` is over; every state, in order.
pub fn follow(
    link: &mut MavlinkLink,
    t0: Instant,
    within: Duration,
    done: impl Fn(&VehicleState) -> bool,
) -> Result<Vec<VehicleState>, String> {
    let mut states = Vec::new();
    loop {
        let s = link
            .state(t0.elapsed().as_secs_f64())
            .map_err(|e| e.to_string())?;
        let over = done(&s);
        states.push(s);
        if over {
            return Ok(states);
        }
        if t0.elapsed() > within {
            let last = states.last();
            return Err(format!("gave up after {within:?}; last state: {last:?}"));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The largest distance between a state's position and the plan's at the state's time, metres,
/// with the state it happened at.
pub fn worst_error(plan: &Trajectory, states: &[VehicleState]) -> Option<(f64, VehicleState)> {
    states
        .iter()
        .map(|s| {
            let want = plan.position_at(s.t_s);
            let d = (0..3)
                .map(|i| (s.position[i] - want[i]).powi(2))
                .sum::<f64>();
            (d.sqrt(), s.clone())
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// The distance between two scenario points, metres.
pub fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// Collects the link's outcomes until `command`'s final one (10 s at most): every outcome with
/// the seconds after `asked` it was collected at.
pub fn settle(
    link: &mut MavlinkLink,
    command: VehicleCommand,
    asked: Instant,
) -> Result<Vec<(f64, LinkOutcome)>, String> {
    let mut seen = Vec::new();
    loop {
        let now = asked.elapsed().as_secs_f64();
        seen.extend(link.outcomes().into_iter().map(|o| (now, o)));
        if seen
            .iter()
            .any(|(_, o)| o.command == command && o.is_final())
        {
            return Ok(seen);
        }
        if now > 10.0 {
            return Err(format!("no final outcome of {command:?}: {seen:?}"));
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}
