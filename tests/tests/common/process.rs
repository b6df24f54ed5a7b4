//! Child processes for the end-to-end tests: running a command with a time limit while draining
//! its output, and locating (and building, once per test process) the `shoal-coordinator` and
//! `shoal-agent` binaries of the profile the tests run in.

use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::OnceLock;
use std::thread;
use std::time::{Duration, Instant};

/// Time limit for one planner run.
pub const RUN_TIMEOUT: Duration = Duration::from_secs(120);
/// Time limit for building the binary.
const BUILD_TIMEOUT: Duration = Duration::from_secs(1200);

/// A finished child process.
pub struct Run {
    /// The command, as `Debug` prints it.
    pub what: String,
    /// How it ended.
    pub status: ExitStatus,
    /// Everything it wrote to stdout.
    pub stdout: String,
    /// Everything it wrote to stderr.
    pub stderr: String,
}

impl Run {
    /// The exit code, `None` when killed by a signal.
    pub fn code(&self) -> Option<i32> {
        self.status.code()
    }
}

impl fmt::Display for Run {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}\nexit status: {}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.what, self.status, self.stdout, self.stderr
        )
    }
}

/// Runs `cmd` to completion, killing it (and failing the test) after `timeout`.
pub fn run(mut cmd: Command, timeout: Duration) -> Run {
    let what = format!("{cmd:?}");
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => panic!("cannot start {what}: {e}"),
    };
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut buf);
            }
            String::from_utf8_lossy(&buf).into_owned()
        })
    };
    let out = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let err = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if start.elapsed() < timeout => thread::sleep(Duration::from_millis(50)),
            Ok(None) => {
                let _ = child.kill();
                let _ = child.wait();
                // Grandchildren may still hold the pipes: give the readers a moment only.
                thread::sleep(Duration::from_millis(500));
                let stdout = if out.is_finished() {
                    out.join().unwrap_or_default()
                } else {
                    String::new()
                };
                let stderr = if err.is_finished() {
                    err.join().unwrap_or_default()
                } else {
                    String::new()
                };
                panic!("{what} did not finish within {timeout:?}; killed\n--- stdout ---\n{stdout}\n--- stderr ---\n{stderr}");
            }
            Err(e) => panic!("cannot wait for {what}: {e}"),
        }
    };
    Run {
        what,
        status,
        stdout: out
            .join()
            .unwrap_or_else(|_| "<stdout reader panicked>".into()),
        stderr: err
            .join()
            .unwrap_or_else(|_| "<stderr reader panicked>".into()),
    }
}

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `target/<profile>/shoal-coordinator`, built once per test process.
///
/// The directory is the parent of the `deps` directory this test executable lives in. The
/// binaries are (re)built with `cargo build -p shoal-coordinator -p shoal-agent` in the same
/// profile so that a stale binary from an earlier build is never tested; this is a no-op when
/// they are up to date.
pub fn coordinator() -> &'static Path {
    &binaries().coordinator
}

/// `target/<profile>/shoal-agent`, built together with [`coordinator`] (the coordinator finds
/// it there when it starts its own agents).
pub fn agent() -> &'static Path {
    &binaries().agent
}

/// The two binaries under test.
pub struct Binaries {
    /// `shoal-coordinator`.
    pub coordinator: PathBuf,
    /// `shoal-agent`.
    pub agent: PathBuf,
}

fn binaries() -> &'static Binaries {
    static BIN: OnceLock<Result<Binaries, String>> = OnceLock::new();
    match BIN.get_or_init(locate_and_build) {
        Ok(b) => b,
        Err(e) => panic!("{e}"),
    }
}

fn locate_and_build() -> Result<Binaries, String> {
    let exe =
        std::env::current_exe().map_err(|e| format!("cannot find the test executable: {e}"))?;
    let deps = exe
        .parent()
        .ok_or_else(|| format!("{} has no parent directory", exe.display()))?;
    let profile_dir = if deps.file_name().is_some_and(|n| n == "deps") {
        deps.parent()
            .ok_or_else(|| format!("{} has no parent directory", deps.display()))?
    } else {
        deps
    };
    let bin = |name: &str| profile_dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    let mut cmd = Command::new(env!("CARGO"));
    // Cargo gives this test process the test crate's package variables (CARGO_MANIFEST_DIR,
    // CARGO_PKG_NAME, ...). Some build scripts (ring's) declare them as inputs, so a nested
    // build that inherits them rebuilds ring, rustls and zenoh, and the next top-level build
    // rebuilds them back: minutes each way.
    for (name, _) in std::env::vars_os() {
        let name = name.to_string_lossy();
        let package_var = ["CARGO_PKG_", "CARGO_BIN_EXE_", "CARGO_CFG_"]
            .iter()
            .any(|p| name.starts_with(p))
            || [
                "CARGO_MANIFEST_DIR",
                "CARGO_MANIFEST_PATH",
                "CARGO_MANIFEST_LINKS",
                "CARGO_CRATE_NAME",
                "CARGO_PRIMARY_PACKAGE",
                "CARGO_TARGET_TMPDIR",
                "OUT_DIR",
            ]
            .contains(&name.as_ref());
        if package_var {
            cmd.env_remove(name.as_ref());
        }
    }
    cmd.current_dir(root()).args([
        "build",
        "-p",
        "shoal-coordinator",
        "-p",
        "shoal-agent",
        "--bin",
        "shoal-coordinator",
        "--bin",
        "shoal-agent",
    ]);
    match profile_dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") | None => {}
        Some("release") => {
            cmd.arg("--release");
        }
        Some(other) => {
            cmd.args(["--profile", other]);
        }
    }
    let build = run(cmd, BUILD_TIMEOUT);
    if !build.status.success() {
        return Err(format!(
            "building shoal-coordinator and shoal-agent failed:\n{build}"
        ));
    }
    let binaries = Binaries {
        coordinator: bin("shoal-coordinator"),
        agent: bin("shoal-agent"),
    };
    for b in [&binaries.coordinator, &binaries.agent] {
        if !b.is_file() {
            return Err(format!(
                "cargo build succeeded but {} does not exist (is CARGO_TARGET_DIR or --target different from this test's?)\n{build}",
                b.display()
            ));
        }
    }
    Ok(binaries)
}
