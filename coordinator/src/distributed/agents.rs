//! The coordinator's own agents (`--agents embedded`, the default): one `shoal-agent` process
//! per vehicle, connected to the embedded router, each logging to `<out>/logs/<vehicle>.log`.
//! They are killed when the plan is done (they also leave by themselves: `--once`), and they
//! leave when this process is gone (`--parent-pid`), however it ended.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use anyhow::Context as _;
use shoal_common::wire::flags::ZenohSecurityArgs;

/// Spawned agent processes, killed on drop.
pub struct LocalAgents {
    children: Vec<(String, Child)>,
}

/// The `shoal-agent` binary: `explicit` if given, else next to this executable (or one level
/// up, for test executables in `target/<profile>/deps`).
pub fn agent_binary(explicit: Option<&Path>) -> anyhow::Result<PathBuf> {
    if let Some(p) = explicit {
        if p.is_file() {
            return Ok(p.to_path_buf());
        }
        anyhow::bail!(
            "--agent-bin (SHOAL_AGENT_BIN) = {}: no such file",
            p.display()
        );
    }
    let name = format!("shoal-agent{}", std::env::consts::EXE_SUFFIX);
    let exe = std::env::current_exe().context("cannot find this executable's directory")?;
    let mut tried = Vec::new();
    for dir in exe.ancestors().skip(1).take(2) {
        let candidate = dir.join(&name);
        if candidate.is_file() {
            return Ok(candidate);
        }
        tried.push(candidate.display().to_string());
    }
    anyhow::bail!(
        "cannot find the shoal-agent binary (looked at {}); build it (`cargo build --release`) \
         or give --agent-bin",
        tried.join(", ")
    )
}

impl LocalAgents {
    /// Starts one agent per vehicle of `vehicles`, connected to `endpoint`.
    pub fn spawn(
        binary: &Path,
        vehicles: &[String],
        endpoint: &str,
        log_dir: &Path,
        extra_args: &[String],
    ) -> anyhow::Result<LocalAgents> {
        std::fs::create_dir_all(log_dir)
            .with_context(|| format!("cannot create the log directory {}", log_dir.display()))?;
        let mut agents = LocalAgents {
            children: Vec::new(),
        };
        for v in vehicles {
            let log_path = log_dir.join(format!("{v}.log"));
            let log = File::create(&log_path)
                .with_context(|| format!("cannot create {}", log_path.display()))?;
            let mut command = Command::new(binary);
            // The coordinator's identity (certificate, password) is not the agents'.
            for var in ZenohSecurityArgs::ENV {
                command.env_remove(var);
            }
            let child = command
                .args(["--vehicle", v, "--connect", endpoint, "--once"])
                // They leave by themselves when this process is gone, even killed by SIGKILL
                // (then `Drop` below cannot run).
                .args(["--parent-pid", &std::process::id().to_string()])
                .args(extra_args)
                // The coordinator's settings must not leak into the agents through SHOAL_*.
                .env_remove("SHOAL_VEHICLE")
                .env_remove("SHOAL_CONNECT")
                .env_remove("SHOAL_THREADS")
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(log)
                .spawn()
                .with_context(|| format!("cannot start {} for {v}", binary.display()))?;
            agents.children.push((v.clone(), child));
        }
        Ok(agents)
    }

    /// Agents that have exited, with how.
    pub fn exited(&mut self) -> Vec<(String, String)> {
        self.children
            .iter_mut()
            .filter_map(|(v, c)| match c.try_wait() {
                Ok(Some(status)) => Some((v.clone(), status.to_string())),
                _ => None,
            })
            .collect()
    }
}

impl Drop for LocalAgents {
    fn drop(&mut self) {
        for (_, child) in &mut self.children {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}
