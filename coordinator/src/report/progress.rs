//! A planner's progress on stderr, in process or over the agents.

use std::io::IsTerminal;

use shoal_common::swarm::IterationReport;

use crate::distributed;

/// Progress on stderr: a bar on a terminal; otherwise a line after the first iteration, every
/// tenth of the run, and at least every `PROGRESS_EVERY` (2 s).
pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    every: usize,
    quiet: bool,
    last: Option<std::time::Instant>,
}

/// Longest silence on a non-terminal stderr during a run.
const PROGRESS_EVERY: std::time::Duration = std::time::Duration::from_secs(2);

impl Progress {
    /// Progress over `iterations`; `quiet` shows nothing.
    pub fn new(iterations: usize, quiet: bool) -> Progress {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(iterations as u64);
            let style = indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} iterations  {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            b.set_style(style);
            b
        });
        Progress {
            bar,
            every: (iterations / 10).max(1),
            quiet,
            last: None,
        }
    }

    /// Shows an in-process iteration.
    pub fn update(&mut self, r: &IterationReport) {
        let msg = format!(
            "best fitness {:.4}, {} evaluations",
            r.best_cost, r.evaluations
        );
        self.show(r.iteration, r.max_iterations, msg);
    }

    /// Shows a distributed exchange round.
    pub fn update_distributed(&mut self, s: &distributed::mission::Status) {
        let msg = format!(
            "best fitness {:.4}, agents alive {}/{}",
            s.best_cost, s.alive, s.vehicles
        );
        self.show(s.iteration, s.max_iterations, msg);
    }

    fn show(&mut self, iteration: usize, max_iterations: usize, msg: String) {
        if let Some(b) = &self.bar {
            b.set_position(iteration as u64);
            b.set_message(msg);
        } else if !self.quiet {
            let due = self.last.is_none_or(|t| t.elapsed() >= PROGRESS_EVERY)
                || iteration.is_multiple_of(self.every)
                || iteration == max_iterations;
            if due {
                eprintln!("iteration {iteration}/{max_iterations}: {msg}");
                self.last = Some(std::time::Instant::now());
            }
        }
    }

    /// Ends the bar (a line-by-line progress has nothing to end).
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
