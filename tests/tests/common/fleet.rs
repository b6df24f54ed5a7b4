//! Background processes for the distributed end-to-end tests: a coordinator and its agents
//! running side by side on loopback, each writing its stdout and stderr to files of its own in a
//! temporary directory.
//!
//! A [`Fleet`] is the guard the dora-rs end-to-end tests use: every process it started is killed
//! when it is dropped, and unless the test called [`Fleet::passed`] first (that is, on a panic, a
//! timeout or an early `?` return) every log is printed, with the logs the processes write
//! themselves (an embedded agent's `out/logs/<vehicle>.log`) registered with [`Fleet::watch`].
//! Every wait takes a deadline and panics when it passes, so no test can hang.

use std::fmt::Write as _;
use std::fs::File;
use std::os::unix::process::ExitStatusExt as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use super::{agent, coordinator, root, scenario, without_shoal_env, Run};

/// How often waits look again.
const POLL: Duration = Duration::from_millis(50);

/// One process of a [`Fleet`], by the order it was started in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Handle(usize);

/// A started process and where its output goes.
struct Proc {
    /// Short name for the logs (`coordinator`, `agent-auv2`, ...).
    name: String,
    /// The command line, as `Debug` prints it.
    what: String,
    child: Child,
    stdout: PathBuf,
    stderr: PathBuf,
    /// How it ended, once known.
    status: Option<ExitStatus>,
}

/// Processes started by one test, killed on drop; their logs are printed unless the test passed.
pub struct Fleet {
    dir: tempfile::TempDir,
    procs: Vec<Proc>,
    /// Log files written by the processes themselves, printed with theirs.
    watched: Vec<PathBuf>,
    passed: bool,
}

/// A loopback TCP port that was free a moment ago (for a `--listen` endpoint).
pub fn free_port() -> u16 {
    let listener = match std::net::TcpListener::bind("127.0.0.1:0") {
        Ok(l) => l,
        Err(e) => panic!("cannot bind a loopback port to find a free one: {e}"),
    };
    match listener.local_addr() {
        Ok(a) => a.port(),
        Err(e) => panic!("cannot read the address of a bound loopback port: {e}"),
    }
}

/// `tcp/127.0.0.1:<port>`.
pub fn endpoint(port: u16) -> String {
    format!("tcp/127.0.0.1:{port}")
}

/// A file's text, or why there is none (logs are read while they are written: never fails).
fn read_lossy(path: &Path) -> String {
    match std::fs::read(path) {
        Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
        Err(e) => format!("<cannot read {}: {e}>", path.display()),
    }
}

impl Fleet {
    /// An empty fleet with a fresh temporary directory for its logs (and the test's outputs).
    pub fn new() -> Fleet {
        let dir = match tempfile::tempdir() {
            Ok(d) => d,
            Err(e) => panic!("cannot create a temporary directory: {e}"),
        };
        Fleet {
            dir,
            procs: Vec::new(),
            watched: Vec::new(),
            passed: false,
        }
    }

    /// The temporary directory (removed on drop).
    pub fn dir(&self) -> &Path {
        self.dir.path()
    }

    /// Starts `cmd` in the background as `name`, stdin closed, stdout and stderr to log files.
    pub fn spawn(&mut self, name: &str, mut cmd: Command) -> Handle {
        let i = self.procs.len();
        let stdout = self.dir().join(format!("{i:02}-{name}.stdout.log"));
        let stderr = self.dir().join(format!("{i:02}-{name}.stderr.log"));
        let what = format!("{cmd:?}");
        let file = |p: &Path| match File::create(p) {
            Ok(f) => f,
            Err(e) => panic!("cannot create the log file {}: {e}", p.display()),
        };
        cmd.stdin(Stdio::null())
            .stdout(file(&stdout))
            .stderr(file(&stderr));
        let child = match cmd.spawn() {
            Ok(c) => c,
            Err(e) => panic!("cannot start {name}: {what}: {e}"),
        };
        self.procs.push(Proc {
            name: name.to_string(),
            what,
            child,
            stdout,
            stderr,
            status: None,
        });
        Handle(i)
    }

    /// Starts `shoal-coordinator plan scenarios/<scenario>.toml --out <out> <extra...>` (no
    /// `--in-process`: distributed), without the caller's `SHOAL_*` variables.
    pub fn coordinator(
        &mut self,
        name: &str,
        scenario_name: &str,
        out: &Path,
        extra: &[&str],
    ) -> Handle {
        self.coordinator_on(name, &scenario(scenario_name), out, extra)
    }

    /// [`Fleet::coordinator`] on a scenario file anywhere.
    pub fn coordinator_on(
        &mut self,
        name: &str,
        scenario_file: &Path,
        out: &Path,
        extra: &[&str],
    ) -> Handle {
        let mut cmd = Command::new(coordinator());
        without_shoal_env(&mut cmd);
        cmd.current_dir(root())
            .arg("plan")
            .arg(scenario_file)
            .arg("--out")
            .arg(out)
            .args(extra);
        self.spawn(name, cmd)
    }

    /// Starts `shoal-agent --vehicle <vehicle> --connect <endpoint> <extra...>` as
    /// `agent-<vehicle>`, without the caller's `SHOAL_*` variables.
    pub fn agent(&mut self, vehicle: &str, endpoint: &str, extra: &[&str]) -> Handle {
        let mut cmd = Command::new(agent());
        without_shoal_env(&mut cmd);
        cmd.current_dir(root())
            .args(["--vehicle", vehicle, "--connect", endpoint])
            .args(extra);
        self.spawn(&format!("agent-{vehicle}"), cmd)
    }

    /// Prints `path` with the logs (a log a process writes itself).
    pub fn watch(&mut self, path: PathBuf) {
        self.watched.push(path);
    }

    fn proc(&self, h: Handle) -> &Proc {
        &self.procs[h.0]
    }

    /// What `h` has written to stderr so far.
    pub fn stderr(&self, h: Handle) -> String {
        read_lossy(&self.proc(h).stderr)
    }

    /// Whether `h` is still running (reaping it if it has ended).
    pub fn running(&mut self, h: Handle) -> bool {
        let p = &mut self.procs[h.0];
        if p.status.is_none() {
            match p.child.try_wait() {
                Ok(s) => p.status = s,
                Err(e) => panic!("cannot wait for {}: {e}", p.name),
            }
        }
        p.status.is_none()
    }

    /// Waits until `h`'s stderr contains `needle`; panics (printing every log) if `h` ends
    /// first or `deadline` passes.
    pub fn wait_for_stderr(&mut self, h: Handle, needle: &str, deadline: Instant) {
        loop {
            if self.stderr(h).contains(needle) {
                return;
            }
            let name = self.proc(h).name.clone();
            if !self.running(h) {
                // One last look: it may have written the line just before it ended.
                if self.stderr(h).contains(needle) {
                    return;
                }
                panic!("{name} ended without writing {needle:?} to stderr");
            }
            if Instant::now() >= deadline {
                panic!("{name} did not write {needle:?} to stderr in time");
            }
            thread::sleep(POLL);
        }
    }

    /// Waits for `h` to end; panics (killing it, printing every log) if `deadline` passes.
    pub fn wait(&mut self, h: Handle, deadline: Instant) -> Run {
        while self.running(h) {
            if Instant::now() >= deadline {
                let p = &self.procs[h.0];
                panic!("{} did not finish in time; killed\n{}", p.name, p.what);
            }
            thread::sleep(POLL);
        }
        let p = self.proc(h);
        Run {
            what: p.what.clone(),
            status: p.status.unwrap_or_else(|| unreachable!("reaped above")),
            stdout: read_lossy(&p.stdout),
            stderr: read_lossy(&p.stderr),
        }
    }

    /// `shoal-coordinator replay LOG`, run to its end (60 s at most); asserts it exits 0 and
    /// finds the figures of the log's end record again.
    pub fn replay(&mut self, log: &Path) -> Run {
        let mut cmd = Command::new(coordinator());
        without_shoal_env(&mut cmd);
        cmd.current_dir(root()).arg("replay").arg(log);
        let h = self.spawn("replay", cmd);
        let r = self.wait(h, Instant::now() + Duration::from_secs(60));
        assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
        assert!(
            r.stdout.contains("the figures match the log's end record"),
            "{}",
            r.stdout
        );
        r
    }

    /// Kills `h` at once (SIGKILL on Unix: no goodbye to the network) and reaps it.
    pub fn kill(&mut self, h: Handle) {
        let p = &mut self.procs[h.0];
        if p.status.is_some() {
            panic!("{} had already ended before the test could kill it", p.name);
        }
        if let Err(e) = p.child.kill() {
            panic!("cannot kill {}: {e}", p.name);
        }
        match p.child.wait() {
            Ok(s) => p.status = Some(s),
            Err(e) => panic!("cannot reap {}: {e}", p.name),
        }
    }

    /// Every process's command, status and output, and every watched log.
    pub fn logs(&self) -> String {
        let mut s = String::new();
        for p in &self.procs {
            let status = p
                .status
                .map_or_else(|| "still running".to_string(), |st| st.to_string());
            let _ = write!(
                s,
                "\n===== {} ({status}) =====\n{}\n--- stdout ---\n{}\n--- stderr ---\n{}",
                p.name,
                p.what,
                read_lossy(&p.stdout),
                read_lossy(&p.stderr)
            );
        }
        for w in &self.watched {
            let _ = write!(s, "\n===== {} =====\n{}", w.display(), read_lossy(w));
        }
        let signalled = self
            .procs
            .iter()
            .any(|p| p.status.is_some_and(|st| st.signal().is_some()));
        if signalled {
            let _ = write!(s, "\n===== the kernel's traps =====\n{}", kernel_traps());
        }
        s
    }

    /// The test passed: drop quietly.
    pub fn passed(&mut self) {
        self.passed = true;
    }
}

impl Default for Fleet {
    fn default() -> Self {
        Fleet::new()
    }
}

impl Drop for Fleet {
    fn drop(&mut self) {
        for p in &mut self.procs {
            if p.status.is_none() {
                let _ = p.child.kill();
                p.status = p.child.wait().ok();
            }
        }
        if thread::panicking() || !self.passed {
            eprintln!(
                "----- logs of every process of the failed test (in {}) -----{}",
                self.dir().display(),
                self.logs()
            );
        }
    }
}

/// The kernel's last lines about processes it trapped (an illegal instruction, a segfault, with
/// the instruction's address), when a process died by a signal; what `dmesg` says otherwise.
fn kernel_traps() -> String {
    match Command::new("dmesg").output() {
        Ok(out) if out.status.success() => {
            let text = String::from_utf8_lossy(&out.stdout);
            let traps: Vec<&str> = text
                .lines()
                .filter(|l| l.contains("trap") || l.contains("segfault") || l.contains("code:"))
                .collect();
            traps[traps.len().saturating_sub(20)..].join("\n")
        }
        Ok(out) => format!("dmesg: {}", String::from_utf8_lossy(&out.stderr).trim()),
        Err(e) => format!("dmesg: {e}"),
    }
}
