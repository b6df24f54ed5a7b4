//! The Python interpreter of Shoal's interop tests, which check Shoal against implementations
//! nobody here wrote (eclipse-zenoh, pymavlink, MAVSDK, geojson, shapely, mcap, jsonschema,
//! websockets; pinned in `tests/python/requirements.txt`), and the browser of the web view's
//! test ([`chromium`]).
//!
//! `$SHOAL_INTEROP_PYTHON` names it when set. Otherwise the first test to ask makes a venv
//! under the workspace's `target/interop-venv` with the pinned packages (one test binary at a
//! time, behind a lock directory) and every later one reuses it while the requirements are
//! unchanged. So `cargo test --workspace` on a fresh machine with Python 3 and the package
//! index runs every interop test: none skips itself; a missing Python is a failure that says
//! what to install.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant, SystemTime};

/// The pinned packages.
pub const REQUIREMENTS: &str = include_str!("../../python/requirements.txt");

/// How long a test waits for another that is making the venv.
const LOCK_WAIT: Duration = Duration::from_secs(900);
/// A lock older than this was left by a test that died: taken over.
const LOCK_STALE: Duration = Duration::from_secs(1200);

/// The interpreter: `$SHOAL_INTEROP_PYTHON`, else the managed venv's (made if needed).
pub fn python() -> Result<String, String> {
    if let Ok(p) = std::env::var("SHOAL_INTEROP_PYTHON") {
        return Ok(p);
    }
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/interop-venv");
    let py = venv.join("bin").join("python");
    let stamp = venv.join("requirements.txt");
    let ready = || py.is_file() && std::fs::read_to_string(&stamp).is_ok_and(|s| s == REQUIREMENTS);
    if ready() {
        return Ok(py.display().to_string());
    }
    let _lock = Lock::take(&venv.with_extension("lock"))?;
    if !ready() {
        make_venv(&venv, &stamp)?;
    }
    Ok(py.display().to_string())
}

/// Debian's `chromium` for the browser tests: the one on `PATH`, else installed with
/// `apt-get install -y chromium` (after an `apt-get update` if the package lists lack it),
/// once, behind the same kind of lock as the venv. The tests drive it over the DevTools
/// protocol from the venv's Python; nothing is downloaded but the Debian package.
pub fn chromium() -> Result<String, String> {
    if let Some(found) = on_path("chromium") {
        return Ok(found);
    }
    let lock = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/chromium.lock");
    let _lock = Lock::take(&lock)?;
    if let Some(found) = on_path("chromium") {
        return Ok(found);
    }
    eprintln!("interop: installing Debian's chromium (apt-get, once)");
    let install = || {
        run(Command::new("apt-get")
            .args(["install", "-y", "chromium"])
            .env("DEBIAN_FRONTEND", "noninteractive"))
    };
    if install().is_err() {
        run(Command::new("apt-get").arg("update"))?;
        install().map_err(|e| {
            format!("{e}: the browser tests need Debian's chromium (apt-get install -y chromium, as root)")
        })?;
    }
    on_path("chromium").ok_or_else(|| "apt-get installed chromium but it is not on PATH".into())
}

/// The first `name` on `PATH`.
fn on_path(name: &str) -> Option<String> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
        .map(|p| p.display().to_string())
}

/// Makes the venv at `venv` with [`REQUIREMENTS`]; writes `stamp` last, once it works.
fn make_venv(venv: &Path, stamp: &Path) -> Result<(), String> {
    let _ = std::fs::remove_dir_all(venv);
    eprintln!("interop: making {} (pip install, once)", venv.display());
    run(Command::new("python3").args(["-m", "venv"]).arg(venv)).map_err(|e| {
        format!("{e}: the interop tests need Python 3 with venv (e.g. Debian's python3-venv)")
    })?;
    let wanted = venv.join("requirements.in");
    std::fs::write(&wanted, REQUIREMENTS).map_err(|e| format!("{}: {e}", wanted.display()))?;
    let pip = venv.join("bin").join("pip");
    run(Command::new(pip)
        .args(["install", "--quiet", "--disable-pip-version-check", "-r"])
        .arg(&wanted))?;
    std::fs::write(stamp, REQUIREMENTS).map_err(|e| format!("{}: {e}", stamp.display()))
}

/// Runs `cmd`; the error shows what it printed.
fn run(cmd: &mut Command) -> Result<(), String> {
    let shown = format!("{cmd:?}");
    let out = cmd.output().map_err(|e| format!("{shown}: {e}"))?;
    if out.status.success() {
        return Ok(());
    }
    let err = String::from_utf8_lossy(&out.stderr);
    Err(format!("{shown}: {}: {err}", out.status))
}

/// A lock held while the venv is made: a directory only one process can create.
struct Lock(PathBuf);

impl Lock {
    fn take(path: &Path) -> Result<Lock, String> {
        let start = Instant::now();
        loop {
            if let Some(parent) = path.parent() {
                let _ = std::fs::create_dir_all(parent);
            }
            match std::fs::create_dir(path) {
                Ok(()) => return Ok(Lock(path.to_path_buf())),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
                Err(e) => return Err(format!("{}: {e}", path.display())),
            }
            let age = std::fs::metadata(path)
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| SystemTime::now().duration_since(t).ok());
            if age.is_some_and(|a| a > LOCK_STALE) {
                let _ = std::fs::remove_dir(path);
                continue;
            }
            if start.elapsed() > LOCK_WAIT {
                return Err(format!(
                    "{}: still locked after {LOCK_WAIT:?}",
                    path.display()
                ));
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir(&self.0);
    }
}
