//! `shoal-coordinator bench-functions`: every optimizer Shoal has on the benchmark functions of
//! Lu et al. 2023, §4 (Table 3, f1–f12) and Hu et al.'s Schaffer F6, with Lu et al. 2023, Table 4's budget
//! (M = 30 particles, t_max = 300 iterations, D = 30 for f1–f8). Prints best / mean / std over the
//! runs like Table 5 and the Wilcoxon rank-sum p-values of IPSO against each other algorithm like
//! Table 6.
//!
//! Every run's seed is a pure function of (base seed, function, run), the same for every
//! algorithm, so the solvers that sample uniformly (IPSO, SPSO, PSO, A-PSO) start from the same
//! swarm in a given run, and results do not depend on the thread count.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use anyhow::{bail, Context};
use shoal_common::benchfns::{self, Benchmark};
use shoal_common::scenario;
use shoal_common::swarm::catalog::{with_solver, MultiSizes, SolverSettings, SolverVisitor};
use shoal_common::swarm::{Executor, Solver, SolverState};

mod markdown;
mod report;
pub use markdown::{markdown, number, HIT_TOLERANCE};
pub use report::{Cell, FunctionInfo, Report, LATE_SHARE, MULTI_POPULATIONS};

/// `shoal-coordinator bench-functions`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchFunctionsArgs {
    /// Independent runs per function and algorithm (Lu et al. 2023, §4: 50).
    #[arg(long, env = "SHOAL_RUNS", default_value_t = 50)]
    pub runs: usize,
    /// Algorithms, comma-separated (default: all): ipso, spso, cbpso, nspso, aco-pso, pso,
    /// epa-pso, ldiw-pso, lcpso, de-pso,
    /// a-pso, mp-pso, amp-pso.
    #[arg(long, env = "SHOAL_ALGORITHMS", value_delimiter = ',')]
    pub algorithms: Vec<String>,
    /// Functions, comma-separated keys or labels (default: all 13): sphere, tablet, rosenbrock,
    /// bent-cigar, rastrigin, griewank, ackley, schwefel, kowalik, six-hump-camel, branin,
    /// hartman6, schaffer-f6 (or f1…f12).
    #[arg(long, env = "SHOAL_FUNCTIONS", value_delimiter = ',')]
    pub functions: Vec<String>,
    /// Base seed; every run's seed is derived from it, the function and the run number.
    #[arg(long, env = "SHOAL_SEED", default_value_t = 1)]
    pub seed: u64,
    /// Dimension D of the scalable functions f1–f8 (Table 4: 30).
    #[arg(long, env = "SHOAL_DIM", default_value_t = 30)]
    pub dim: usize,
    /// Iterations t_max (Table 4: 300).
    #[arg(long, env = "SHOAL_ITERATIONS", default_value_t = 300)]
    pub iterations: usize,
    /// Particles M per run (Table 4: 30); multi-population solvers split them (see the legend).
    #[arg(long, env = "SHOAL_PARTICLES", default_value_t = 30)]
    pub particles: usize,
    /// Velocity cap of every solver, as a fraction of each dimension's range (no seed gives
    /// one). Default: each solver's own — 0.1 for Zhi & Zuo's, 0.2 for the others.
    #[arg(long, env = "SHOAL_MAX_VELOCITY_FRACTION")]
    pub max_velocity_fraction: Option<f64>,
    /// Worker threads (default: all cores); the results do not depend on it.
    #[arg(long, env = "SHOAL_THREADS")]
    pub threads: Option<usize>,
    /// Also write the markdown report to this file.
    #[arg(long, env = "SHOAL_BENCH_OUT")]
    pub out: Option<PathBuf>,
    /// No per-run progress on stderr.
    #[arg(long, short, env = "SHOAL_QUIET")]
    pub quiet: bool,
}

/// What one run needs besides the function and the seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSettings {
    /// Particles M.
    pub particles: usize,
    /// Iterations t_max.
    pub iterations: usize,
    /// Velocity cap for every solver (a fraction of each range); `None`: each solver's own.
    pub velocity_cap: Option<f64>,
}

/// What one run gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunResult {
    /// Best cost found.
    pub best: f64,
    /// Cost evaluations spent.
    pub evaluations: u64,
    /// The best still improved over the last tenth of the iterations ([`still_improving`]).
    pub still_improving: bool,
}

/// True when a run's best improved over the last [`LATE_SHARE`] of its iterations by more than
/// 1e-9 of max(1, |best|): the budget, not the optimizer, ended it, and more iterations would
/// likely give a better best (Kowalik at Table 4's budget is the case in point). The floor of 1
/// keeps a run crawling from 1e-80 to 1e-82 on the Sphere from counting. `convergence` is the
/// best after each iteration.
pub fn still_improving(convergence: &[f64]) -> bool {
    let n = convergence.len();
    if n < 2 {
        return false;
    }
    let window = ((n as f64 * LATE_SHARE).ceil() as usize).clamp(1, n - 1);
    let (before, end) = (convergence[n - 1 - window], convergence[n - 1]);
    before - end > 1e-9 * end.abs().max(1.0)
}

/// An optimizer the suite can run: a catalog algorithm and its legend line.
#[derive(Debug, Clone, Copy)]
pub struct Algorithm {
    /// Name on the command line and in the tables.
    pub name: &'static str,
    /// Settings, for the legend.
    pub about: &'static str,
    /// The algorithm the catalog builds the solver of.
    pub algorithm: scenario::Algorithm,
}

impl Algorithm {
    /// One run on a function with a seed.
    pub fn run(&self, f: &dyn Benchmark, settings: RunSettings, seed: u64) -> RunResult {
        let solver = SolverSettings {
            particles: settings.particles,
            multi: split(settings.particles),
            threads: 1,
            seed,
            velocity_cap: settings.velocity_cap,
        };
        let run = BenchRun {
            f,
            iterations: settings.iterations,
        };
        with_solver(self.algorithm, &solver, run)
    }
}

/// Every optimizer Shoal has, in table order (Lu et al.'s five, Zhi & Zuo's four, Zhang et al.'s
/// EPA-PSO, Hu et al.'s three). A new solver is one line here, once it is in the catalog.
pub fn solvers() -> Vec<Algorithm> {
    let a = |algorithm: scenario::Algorithm, about| Algorithm {
        name: algorithm.as_str(),
        about,
        algorithm,
    };
    vec![
        a(
            scenario::Algorithm::Ipso,
            "Lu et al. 2023 IPSO, Table 4: c1, c2 2 → 0.5, ω ∈ [0.4, 0.9] by fitness, p = 5 %",
        ),
        a(
            scenario::Algorithm::Spso,
            "Lu et al. 2023 SPSO, Table 4: ω = 0.5, c1 = c2 = 2",
        ),
        a(
            scenario::Algorithm::Cbpso,
            "Lu et al. 2023 CBPSO, Table 4: chaotic start (μ = 4), ω 0.9 → 0.4, c1 = c2 = 2",
        ),
        a(
            scenario::Algorithm::Nspso,
            "Lu et al. 2023 NSPSO, Table 4: ω 0.9 → 0.4, c1 = c2 = 2, one objective",
        ),
        a(
            scenario::Algorithm::AcoPso,
            "Lu et al. 2023 ACO-PSO, Table 4: SPSO + continuous ant colony (α = 1, β = 5, ρ = 0.5)",
        ),
        a(
            scenario::Algorithm::Pso,
            "Zhi & Zuo 2024 PSO, Table 5 coefficients: ω = 0.15, c1 = c2 = 1.5",
        ),
        a(
            scenario::Algorithm::APso,
            "Zhi & Zuo 2024 A-PSO: eq. (7) adaptive coefficients, one population",
        ),
        a(
            scenario::Algorithm::MpPso,
            "Zhi & Zuo 2024 MP-PSO: Table 5 coefficients, M split as below",
        ),
        a(
            scenario::Algorithm::AmpPso,
            "Zhi & Zuo 2024 AMP-PSO: eq. (7)–(8), M split as below",
        ),
        a(
            scenario::Algorithm::EpaPso,
            "Zhang et al. 2022 EPA-PSO, Table 2: velocity jump, eq. (16) schedule, eq. (17) restarts",
        ),
        a(
            scenario::Algorithm::LdiwPso,
            "Hu et al. 2023 LDIW-PSO, Table 5: ω 0.9 → 0.4, c1 = 2, c2 = 1.5",
        ),
        a(
            scenario::Algorithm::Lcpso,
            "Hu et al. 2023 LCPSO, Table 5: logistic-chaos inertia (eq. 4–10)",
        ),
        a(
            scenario::Algorithm::DePso,
            "Hu et al. 2023 DE-PSO, Table 5: PSO move + DE/best/1/bin (F = 0.8, CR = 0.6); 2 evaluations per particle per iteration",
        ),
    ]
}

/// Sizes a multi-population solver to about `m` particles in all, so it gets the same budget as
/// the single-population ones instead of Table 5's 20 × 50 + 20: five followers of ⌊m/6⌋
/// particles and a leader with the rest (m = 30: 5 × 5 + 5), exchanging every iteration. Each
/// iteration also moves the five immigrants, so it costs m + 5 evaluations (35 instead of 30).
/// One thread: the suite runs whole runs in parallel instead.
pub fn split(particles: usize) -> MultiSizes {
    let each = (particles / (MULTI_POPULATIONS + 1)).max(2);
    MultiSizes {
        populations: MULTI_POPULATIONS,
        particles: each,
        leader_particles: particles.saturating_sub(MULTI_POPULATIONS * each).max(1),
        exchange_every: 1,
    }
}

/// One run of the visited solver on `f` with the suite's budget.
struct BenchRun<'a> {
    /// The function.
    f: &'a dyn Benchmark,
    /// Iterations t_max.
    iterations: usize,
}

impl<'a> SolverVisitor<&'a dyn Benchmark> for BenchRun<'a> {
    type Output = RunResult;
    fn visit<S: Solver<&'a dyn Benchmark>>(self, mut solver: S) -> RunResult {
        let out = Executor::new(self.iterations).run(&self.f, &mut solver, |_| {});
        RunResult {
            best: out.state.best_cost(),
            evaluations: out.state.evaluations(),
            still_improving: still_improving(&out.convergence),
        }
    }
}

/// Seed of run `run` of function number `function`: SplitMix64 of the three, so neighbouring
/// runs get unrelated streams.
pub fn run_seed(base: u64, function: usize, run: usize) -> u64 {
    let mut z = base
        ^ (function as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (run as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A finished run, for progress reports.
#[derive(Debug, Clone)]
pub struct RunReport<'a> {
    /// Runs finished so far (this one included).
    pub done: usize,
    /// Runs in the suite.
    pub total: usize,
    /// Function label and name.
    pub function: &'a str,
    /// Algorithm.
    pub algorithm: &'a str,
    /// Run number, 1-based.
    pub run: usize,
    /// Its best cost.
    pub best: f64,
}

/// Runs the suite `args` describes; `progress` is called after every run, from worker threads.
/// `stop` ends it early: runs not started are left out of the report.
pub fn bench_functions(
    args: &BenchFunctionsArgs,
    stop: &AtomicBool,
    progress: &(dyn Fn(&RunReport) + Sync),
) -> anyhow::Result<Report> {
    if args.runs == 0 || args.iterations == 0 {
        bail!("--runs and --iterations must be at least 1");
    }
    if args.particles < 2 {
        bail!("--particles = {}: a swarm needs at least 2", args.particles);
    }
    if args.dim < 2 {
        bail!(
            "--dim = {}: the scalable functions need at least 2",
            args.dim
        );
    }
    let threads = match args.threads {
        Some(0) => bail!("--threads must be at least 1"),
        Some(t) => t,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let functions = pick_functions(&args.functions, args.dim)?;
    let algorithms = pick_algorithms(&args.algorithms)?;
    if let Some(cap) = args.max_velocity_fraction {
        if !shoal_common::swarm::is_valid_velocity_cap(cap) {
            bail!("--max-velocity-fraction = {cap}: must be in (0, 1]");
        }
    }
    let settings = RunSettings {
        particles: args.particles,
        iterations: args.iterations,
        velocity_cap: args.max_velocity_fraction,
    };
    // Seeds follow a function's place in the whole table, not in the selection, so
    // `--functions kowalik` repeats exactly the Kowalik runs of the full suite.
    let table_index: Vec<usize> = functions.iter().map(|f| table_position(f.key())).collect();
    let (nf, na, nr) = (functions.len(), algorithms.len(), args.runs);
    let total = nf * na * nr;
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let names: Vec<String> = functions
        .iter()
        .map(|f| format!("{} {}", f.label(), f.name()))
        .collect();
    // Job k is (function, algorithm, run) in that nesting; each worker takes the next job and
    // keeps (k, result), so what a job computes never depends on which thread ran it.
    let worker = || {
        let mut out = Vec::new();
        loop {
            if stop.load(Ordering::Relaxed) {
                break;
            }
            let k = next.fetch_add(1, Ordering::Relaxed);
            if k >= total {
                break;
            }
            let (fi, ai, r) = (k / (na * nr), (k / nr) % na, k % nr);
            let seed = run_seed(args.seed, table_index[fi], r);
            let result = algorithms[ai].run(functions[fi].as_ref(), settings, seed);
            progress(&RunReport {
                done: done.fetch_add(1, Ordering::Relaxed) + 1,
                total,
                function: &names[fi],
                algorithm: algorithms[ai].name,
                run: r + 1,
                best: result.best,
            });
            out.push((k, result));
        }
        out
    };
    let mut results: Vec<(usize, RunResult)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads.min(total).max(1))
            .map(|_| scope.spawn(worker))
            .collect();
        handles
            .into_iter()
            // A panic in a solver is a bug; re-raise it here.
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    results.sort_by_key(|(k, _)| *k);
    let mut cells = vec![vec![Cell::default(); na]; nf];
    let complete = results.len() == total;
    for (k, r) in results {
        let cell = &mut cells[k / (na * nr)][(k / nr) % na];
        cell.values.push(r.best);
        cell.evaluations.push(r.evaluations);
        cell.still_improving.push(r.still_improving);
    }
    Ok(Report {
        runs: nr,
        particles: args.particles,
        iterations: args.iterations,
        seed: args.seed,
        velocity_cap: args.max_velocity_fraction,
        functions: functions
            .iter()
            .map(|f| FunctionInfo {
                key: f.key().to_string(),
                label: f.label().to_string(),
                name: f.name().to_string(),
                dim: f.dim(),
                optimum: f.optimum(),
                scalable: benchfns::KEYS[..8].contains(&f.key()),
            })
            .collect(),
        algorithms: algorithms.iter().map(|a| a.name).collect(),
        about: algorithms.iter().map(|a| a.about).collect(),
        cells,
        complete,
    })
}

fn pick_functions(keys: &[String], dim: usize) -> anyhow::Result<Vec<Box<dyn Benchmark>>> {
    if keys.is_empty() {
        return Ok(benchfns::all(dim));
    }
    let mut picked: Vec<Box<dyn Benchmark>> = Vec::new();
    for k in keys {
        let Some(f) = benchfns::by_key(k.trim(), dim) else {
            bail!(
                "unknown function {k:?}; known: {} (or f1…f12)",
                benchfns::KEYS.join(", ")
            );
        };
        if !picked.iter().any(|p| p.key() == f.key()) {
            picked.push(f);
        }
    }
    // Table order, whatever the order on the command line.
    picked.sort_by_key(|f| table_position(f.key()));
    Ok(picked)
}

/// Place of the function `key` in the whole suite (table order).
fn table_position(key: &str) -> usize {
    benchfns::KEYS
        .iter()
        .position(|k| *k == key)
        .unwrap_or(benchfns::KEYS.len())
}

fn pick_algorithms(names: &[String]) -> anyhow::Result<Vec<Algorithm>> {
    let all = solvers();
    if names.is_empty() {
        return Ok(all);
    }
    for n in names {
        if !all.iter().any(|a| a.name == n.trim()) {
            let known: Vec<&str> = all.iter().map(|a| a.name).collect();
            bail!("unknown algorithm {n:?}; known: {}", known.join(", "));
        }
    }
    Ok(all
        .into_iter()
        .filter(|a| names.iter().any(|n| n.trim() == a.name))
        .collect())
}

/// The command: runs the suite, prints the report on stdout (and to `--out`), progress on stderr.
pub fn command(args: &BenchFunctionsArgs, stop: &AtomicBool) -> anyhow::Result<i32> {
    let started = std::time::Instant::now();
    let quiet = args.quiet;
    let report = bench_functions(args, stop, &|p| {
        if !quiet {
            eprintln!(
                "[{}/{}] {} {} run {}: best {:e}",
                p.done, p.total, p.function, p.algorithm, p.run, p.best
            );
        }
    })?;
    let text = markdown(&report);
    {
        use std::io::Write;
        let mut out = std::io::stdout().lock();
        // A closed pipe (`| head`) is not an error worth a panic.
        let _ = out.write_all(text.as_bytes()).and_then(|()| out.flush());
    }
    if let Some(path) = &args.out {
        std::fs::write(path, &text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    let mut note = String::new();
    let _ = write!(
        note,
        "bench-functions: {} runs in {:.1} s",
        report
            .cells
            .iter()
            .flatten()
            .map(|c| c.values.len())
            .sum::<usize>(),
        started.elapsed().as_secs_f64()
    );
    if !report.complete {
        note.push_str(" (interrupted: the tables hold only the runs that finished)");
    }
    eprintln!("{note}");
    Ok(crate::commands::exit::EXIT_FEASIBLE)
}

#[cfg(test)]
mod tests {
    use super::still_improving;

    #[test]
    fn a_run_still_improves_when_its_last_tenth_lowered_the_best_beyond_the_tolerance() {
        // 20 iterations: the window is the last 2, from index 17 to 19.
        let mut c = vec![5.0; 20];
        c[18] = 4.0;
        c[19] = 4.0;
        assert!(still_improving(&c), "5 → 4 within the last 2 iterations");
        // The fall came at index 17, before the window started: no longer improving.
        c[17] = 4.0;
        assert!(!still_improving(&c));
        // Kowalik's scale: a fall of 1e-7 near 3.1e-4 counts (tolerance 1e-9 of max(1, 3.1e-4)).
        let mut k = vec![3.1017e-4; 10];
        k[9] = 3.1016e-4;
        assert!(still_improving(&k));
        // The Sphere crawling from 1e-80 to 1e-82 does not (below the floor of 1e-9).
        let mut z = vec![1e-80; 10];
        z[9] = 1e-82;
        assert!(!still_improving(&z));
        // A big cost falling by less than 1e-9 of itself does not either: 1e6 → 1e6 − 1e-4.
        let mut b = vec![1e6; 10];
        b[9] = 1e6 - 1e-4;
        assert!(!still_improving(&b));
        b[9] = 1e6 - 1e-2;
        assert!(still_improving(&b));
        // Too short to tell.
        assert!(!still_improving(&[1.0]));
        assert!(still_improving(&[2.0, 1.0]));
    }
}
