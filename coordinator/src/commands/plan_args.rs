//! The planning flags `plan` and `run` share (each flattens [`PlanArgs`]), and the one place
//! they become [`MissionOptions`] ([`PlanArgs::options`]). Flags only: no command's handler
//! lives here.

use std::path::PathBuf;

use shoal_common::scenario::Algorithm;
use shoal_common::wire::flags::{ZenohListen, ZenohSecurityArgs};

use crate::distributed::AgentsMode;
use crate::mission::options::{
    default_listen, seconds, DEFAULT_JOIN_TIMEOUT_S, DEFAULT_ROUND_TIMEOUT_S,
};
use crate::mission::{MissionOptions, NetworkOptions, Overrides};

/// `--listen`'s help under `plan` and `run`, whose default depends on `--agents`.
const LISTEN_HELP: &str = "Distributed mode: endpoint(s) the embedded Zenoh router listens on (comma-separated). \
Default: tcp/127.0.0.1:0 (a free port) with embedded agents, tcp/127.0.0.1:7447 with external ones; \
listening beyond loopback needs authentication (or --insecure)";

/// `shoal-coordinator plan`.
#[derive(Debug, Clone, clap::Args)]
#[command(mut_arg("listen", |a| a.default_value(Option::<&str>::None).help(LISTEN_HELP)))]
pub struct PlanArgs {
    /// Scenario file (TOML).
    #[arg(env = "SHOAL_SCENARIO")]
    pub scenario: PathBuf,
    /// Directory for plan.json and plan.svg (created if missing).
    #[arg(long, env = "SHOAL_OUT", default_value = "out")]
    pub out: PathBuf,
    /// Plan inside this process (no agents, no network).
    #[arg(long, env = "SHOAL_IN_PROCESS")]
    pub in_process: bool,
    /// RNG seed (overrides the scenario's).
    #[arg(long, env = "SHOAL_SEED")]
    pub seed: Option<u64>,
    /// Optimizer: amp-pso, a-pso, mp-pso, pso (Zhi & Zuo 2024); ipso, spso, cbpso, nspso, aco-pso
    /// (Lu et al. 2023); epa-pso, pso-length, m-pso (Zhang et al. 2022, one AUV, with --in-process); de-pso,
    /// ldiw-pso, lcpso (Hu et al. 2023 inspection tours, in process or by the agents); cf-pso
    /// (Clerc and Kennedy 2002, with --in-process); overrides the scenario's.
    #[arg(long, env = "SHOAL_ALGORITHM")]
    pub algorithm: Option<Algorithm>,
    /// Iterations (overrides the scenario's).
    #[arg(long, env = "SHOAL_ITERATIONS")]
    pub iterations: Option<usize>,
    /// Follower populations (overrides the scenario's).
    #[arg(long, env = "SHOAL_POPULATIONS")]
    pub populations: Option<usize>,
    /// Particles per population (overrides the scenario's).
    #[arg(long, env = "SHOAL_PARTICLES")]
    pub particles: Option<usize>,
    /// Worker threads (overrides the scenario's; the plan does not depend on it).
    #[arg(long, env = "SHOAL_THREADS")]
    pub threads: Option<usize>,
    /// No progress output on stderr.
    #[arg(long, short, env = "SHOAL_QUIET")]
    pub quiet: bool,
    /// Fleet plans: keep the swarm's own best even when it breaks a limit, instead of
    /// re-planning each vehicle in a violation against the others' paths afterwards (the
    /// scenario's `optimizer.touch_up`).
    #[arg(long, env = "SHOAL_NO_TOUCH_UP")]
    pub no_touch_up: bool,
    /// Fleet plans: keep the swarm's plan as it ends, without pulling each path tight inside
    /// its limits and the fleet's separation by a local constrained search afterwards (the
    /// scenario's `optimizer.refine`).
    #[arg(long, env = "SHOAL_NO_REFINE")]
    pub no_refine: bool,
    /// Distributed mode: start one agent per vehicle here (embedded) or wait for agents started
    /// elsewhere to connect (external).
    #[arg(long, env = "SHOAL_AGENTS", value_enum, default_value_t = AgentsMode::Embedded)]
    pub agents: AgentsMode,
    /// Distributed mode: where the embedded router listens (empty: [`default_listen`]).
    #[command(flatten)]
    pub listen: ZenohListen,
    /// Distributed mode: other Zenoh routers to link to, e.g. another coordinator's endpoint, so
    /// two missions share one network and its agents (comma-separated).
    #[arg(long, env = "SHOAL_ROUTERS", value_delimiter = ',')]
    pub router: Vec<String>,
    /// Distributed mode: how members authenticate to the embedded router (listening beyond
    /// loopback needs it, or --insecure).
    #[command(flatten)]
    pub zenoh: ZenohSecurityArgs,
    /// Distributed mode: seconds the agents have to join.
    #[arg(long, env = "SHOAL_JOIN_TIMEOUT", default_value_t = DEFAULT_JOIN_TIMEOUT_S)]
    pub join_timeout: f64,
    /// Distributed mode: seconds a round waits for an agent's elites before the coordinator
    /// plans that vehicle itself (degraded mode).
    #[arg(long, env = "SHOAL_ROUND_TIMEOUT", default_value_t = DEFAULT_ROUND_TIMEOUT_S)]
    pub round_timeout: f64,
    /// Distributed mode: mission id (default: scenario name, process id and time).
    #[arg(long, env = "SHOAL_MISSION")]
    pub mission: Option<String>,
    /// Distributed mode: the shoal-agent binary for embedded agents (default: next to this one).
    #[arg(long, env = "SHOAL_AGENT_BIN")]
    pub agent_bin: Option<PathBuf>,
    /// Distributed mode: rewrite this file every 2 s while the router is open (for container
    /// healthchecks: `shoal-coordinator health`).
    #[arg(long, env = "SHOAL_HEALTH_FILE")]
    pub health_file: Option<PathBuf>,
}

impl PlanArgs {
    /// The mission these flags ask for. The network's settings (the password file read, the
    /// timeouts checked) only when they are used: over the agents, or for `run`'s execution
    /// (`network`).
    pub fn options(&self, network: bool) -> anyhow::Result<MissionOptions> {
        Ok(MissionOptions {
            scenario: self.scenario.clone(),
            out: self.out.clone(),
            overrides: Overrides {
                seed: self.seed,
                algorithm: self.algorithm,
                iterations: self.iterations,
                populations: self.populations,
                particles: self.particles,
                threads: self.threads,
                no_touch_up: self.no_touch_up,
                no_refine: self.no_refine,
            },
            quiet: self.quiet,
            in_process: self.in_process,
            network: if network || !self.in_process {
                Some(self.network()?)
            } else {
                None
            },
        })
    }

    /// The distributed-mode flags as network settings.
    fn network(&self) -> anyhow::Result<NetworkOptions> {
        let listen = if self.listen.listen.is_empty() {
            vec![default_listen(self.agents).to_string()]
        } else {
            self.listen.listen.clone()
        };
        Ok(NetworkOptions {
            mission: self.mission.clone(),
            agents: self.agents,
            listen,
            routers: self.router.clone(),
            security: self.zenoh.security()?,
            join_timeout: seconds("--join-timeout (SHOAL_JOIN_TIMEOUT)", self.join_timeout)?,
            round_timeout: seconds("--round-timeout (SHOAL_ROUND_TIMEOUT)", self.round_timeout)?,
            agent_bin: self.agent_bin.clone(),
            health_file: self.health_file.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// `plan`'s flags alone, parsed as the command line would be.
    #[derive(Parser)]
    struct Plan {
        #[command(flatten)]
        args: PlanArgs,
    }

    /// The command line's surface: `--listen` has no default under `plan` (it follows
    /// `--agents`), and the flags land in the options.
    #[test]
    fn the_flags_become_the_options() -> anyhow::Result<()> {
        let line = [
            "plan",
            "s.toml",
            "--seed",
            "4",
            "--agents",
            "external",
            "--no-touch-up",
        ];
        let o = Plan::try_parse_from(line)?.args.options(false)?;
        assert_eq!(o.overrides.seed, Some(4));
        assert!(o.overrides.no_touch_up);
        let n = o.network()?;
        assert_eq!(n.listen, ["tcp/127.0.0.1:7447"]);
        assert_eq!(n.join_timeout.as_secs_f64(), DEFAULT_JOIN_TIMEOUT_S);
        let o = Plan::try_parse_from(["plan", "s.toml", "--in-process"])?
            .args
            .options(false)?;
        assert!(o.in_process && o.network.is_none());
        let e = Plan::try_parse_from(["plan", "s.toml", "--join-timeout=-1"])?
            .args
            .options(false)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.contains("--join-timeout (SHOAL_JOIN_TIMEOUT) = -1"),
            "{e}"
        );
        Ok(())
    }
}
