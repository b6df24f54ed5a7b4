//! The one place that maps an algorithm's name to a configured solver: the [`Algorithm`] a
//! scenario names (and the [`LegAlgorithm`] of a tour leg), the planner [`Family`] it belongs
//! to, and, through [`with_solver`], the solver with its paper's settings. The in-process
//! planners, the tours, the distributed followers and leader and the benchmarks all come here
//! instead of matching on names, so a new optimizer is one file in `solvers/` plus an entry
//! here (docs/guide/new-optimizer.md).
//!
//! [`with_solver`] hands the solver to a [`SolverVisitor`] rather than returning a boxed one:
//! every solver has its own state type, and a generic visit keeps the run monomorphised, the
//! same code and the same random draws as naming the solver directly.

use serde::{Deserialize, Serialize};

use super::core::population::{Coefficients, Schedule};
use super::core::{Problem, Solver, VelocityCapped};
use super::solvers::acopso::AcoPso;
use super::solvers::cbpso::Cbpso;
use super::solvers::cfpso::CfPso;
use super::solvers::depso::DePso;
use super::solvers::epapso::EpaPso;
use super::solvers::ipso::Ipso;
use super::solvers::lcpso::Lcpso;
use super::solvers::ldiwpso::LdiwPso;
use super::solvers::multi::{MultiPso, AMP_PSO_VELOCITY_CAP};
use super::solvers::nspso::Nspso;
use super::solvers::pso::Pso;

/// The optimizers `plan` can run.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Algorithm {
    /// Adaptive multi-population PSO (Zhi & Zuo 2024).
    #[default]
    AmpPso,
    /// Classic single-population PSO with fixed coefficients (Table 5).
    Pso,
    /// Multi-population PSO with fixed coefficients, c3 = 1.5 (Table 5).
    MpPso,
    /// Single-population PSO with the adaptive coefficients of eq. (7) (Table 5).
    APso,
    /// Improved PSO of Lu et al. 2023 (eq. (19)–(26), Table 8).
    Ipso,
    /// Standard PSO of Lu et al. 2023, Table 8 (c1 = c2 = 2, w = 0.5).
    Spso,
    /// Chaos-initialised PSO of Lu et al. 2023, Table 8.
    Cbpso,
    /// Non-dominated sorting PSO of Lu et al. 2023, Table 8.
    Nspso,
    /// Ant-colony / PSO hybrid of Lu et al. 2023, Table 8.
    AcoPso,
    /// Energy-saving PSO of Zhang et al. 2022 (eq. (14)–(17), Table 2), one AUV in a current.
    EpaPso,
    /// Zhang et al.'s baseline: PSO minimising the path length alone.
    PsoLength,
    /// Zhang et al.'s M-PSO: the same PSO on the full cost of eq. (6).
    MPso,
    /// Hu et al.'s DE-PSO cage-inspection tours (eq. (14)–(20), Table 5).
    DePso,
    /// Hu et al.'s LDIW-PSO baseline (eq. (3)).
    LdiwPso,
    /// Hu et al.'s LCPSO baseline (eq. (4)–(10)).
    Lcpso,
    /// Constriction-factor PSO of Clerc and Kennedy (2002), χ ≈ 0.7298, c1 = c2 = 2.05.
    CfPso,
}

impl Algorithm {
    /// Name as written in files and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Algorithm::AmpPso => "amp-pso",
            Algorithm::Pso => "pso",
            Algorithm::MpPso => "mp-pso",
            Algorithm::APso => "a-pso",
            Algorithm::Ipso => "ipso",
            Algorithm::Spso => "spso",
            Algorithm::Cbpso => "cbpso",
            Algorithm::Nspso => "nspso",
            Algorithm::AcoPso => "aco-pso",
            Algorithm::EpaPso => "epa-pso",
            Algorithm::PsoLength => "pso-length",
            Algorithm::MPso => "m-pso",
            Algorithm::DePso => "de-pso",
            Algorithm::LdiwPso => "ldiw-pso",
            Algorithm::Lcpso => "lcpso",
            Algorithm::CfPso => "cf-pso",
        }
    }
    /// Every algorithm: Zhi & Zuo 2024, Table 5's order, then Lu et al. 2023, Table 8's, Zhang et al.'s, Hu et al.'s,
    /// then the variants from the wider literature.
    pub const ALL: [Algorithm; 16] = [
        Algorithm::AmpPso,
        Algorithm::APso,
        Algorithm::MpPso,
        Algorithm::Pso,
        Algorithm::Ipso,
        Algorithm::Spso,
        Algorithm::Cbpso,
        Algorithm::Nspso,
        Algorithm::AcoPso,
        Algorithm::EpaPso,
        Algorithm::PsoLength,
        Algorithm::MPso,
        Algorithm::DePso,
        Algorithm::LdiwPso,
        Algorithm::Lcpso,
        Algorithm::CfPso,
    ];
    /// True for Zhang et al.'s single-AUV energy planners, which plan on the energy cost rather
    /// than the fleet fitness.
    pub fn is_energy_planner(self) -> bool {
        matches!(family(self), Family::Energy { .. })
    }
    /// True for Hu et al.'s inspection-tour planners (the leg swarm is the algorithm).
    pub fn is_tour_planner(self) -> bool {
        matches!(family(self), Family::Tour(_))
    }
    /// True for the multi-population algorithms (the ones a distributed run can split).
    pub fn is_multi_population(self) -> bool {
        matches!(
            family(self),
            Family::Fleet {
                multi_population: true
            }
        )
    }
}

impl std::str::FromStr for Algorithm {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Algorithm::ALL
            .into_iter()
            .find(|a| a.as_str() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Algorithm::ALL.iter().map(|a| a.as_str()).collect();
                format!(
                    "unknown algorithm `{s}` (expected one of {})",
                    names.join(", ")
                )
            })
    }
}

/// Which planner an algorithm runs under: the problem it optimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// Zhi & Zuo's and Lu et al.'s fleet planners, on the fleet fitness of Zhi & Zuo 2024, eq. (12).
    Fleet {
        /// Followers and a leader (AMP-PSO, MP-PSO): the algorithms a distributed run splits.
        multi_population: bool,
    },
    /// Zhang et al.'s single-AUV planners, on the energy cost.
    Energy {
        /// The baseline that minimises the path length alone rather than eq. (6).
        path_length_only: bool,
    },
    /// Hu et al.'s inspection tours: the algorithm is the swarm that plans each leg.
    Tour(LegAlgorithm),
}

/// The planner family of `algorithm`.
pub fn family(algorithm: Algorithm) -> Family {
    use Algorithm as A;
    match algorithm {
        A::AmpPso | A::MpPso => Family::Fleet {
            multi_population: true,
        },
        A::Pso | A::APso | A::Ipso | A::Spso | A::Cbpso | A::Nspso | A::AcoPso | A::CfPso => {
            Family::Fleet {
                multi_population: false,
            }
        }
        A::EpaPso | A::MPso => Family::Energy {
            path_length_only: false,
        },
        A::PsoLength => Family::Energy {
            path_length_only: true,
        },
        A::DePso => Family::Tour(LegAlgorithm::DePso),
        A::LdiwPso => Family::Tour(LegAlgorithm::LdiwPso),
        A::Lcpso => Family::Tour(LegAlgorithm::Lcpso),
    }
}

/// The swarm that plans the legs of a tour (the three algorithms of Hu et al. 2023, Table 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LegAlgorithm {
    /// DE-PSO, §IV-A, eq. (14)–(20).
    DePso,
    /// LDIW-PSO, eq. (3).
    LdiwPso,
    /// LCPSO, eq. (4)–(10).
    Lcpso,
}

impl LegAlgorithm {
    /// The scenario algorithm that plans tours with this leg swarm.
    pub fn algorithm(self) -> Algorithm {
        match self {
            LegAlgorithm::DePso => Algorithm::DePso,
            LegAlgorithm::LdiwPso => Algorithm::LdiwPso,
            LegAlgorithm::Lcpso => Algorithm::Lcpso,
        }
    }

    /// The solver's name ("de-pso", "ldiw-pso", "lcpso").
    pub fn name(&self) -> &'static str {
        self.algorithm().as_str()
    }
}

/// The leg swarm of an algorithm (`None` for the algorithms that do not plan tours).
pub fn leg_algorithm(algorithm: Algorithm) -> Option<LegAlgorithm> {
    match family(algorithm) {
        Family::Tour(leg) => Some(leg),
        _ => None,
    }
}

/// The coefficients of a multi-population algorithm's followers and leader: eq. (7)–(8) for
/// the adaptive ones (AMP-PSO, A-PSO), Table 5's fixed ones otherwise.
pub fn schedule(algorithm: Algorithm) -> Schedule {
    match algorithm {
        Algorithm::AmpPso | Algorithm::APso => Schedule::Adaptive,
        _ => Schedule::TABLE5_FIXED,
    }
}

/// Sizes of the multi-population solvers (AMP-PSO, MP-PSO); the others ignore them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MultiSizes {
    /// Follower populations.
    pub populations: usize,
    /// Particles per follower population.
    pub particles: usize,
    /// The leader's own particles, besides the immigrants.
    pub leader_particles: usize,
    /// Exchange period, iterations.
    pub exchange_every: usize,
}

/// What a solver is built with besides its paper's coefficients: what a scenario's optimizer
/// settings, a tour leg or a benchmark run give.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Particles of a single-population solver.
    pub particles: usize,
    /// Sizes of a multi-population solver.
    pub multi: MultiSizes,
    /// Threads a multi-population solver steps its populations on (results do not depend on
    /// it).
    pub threads: usize,
    /// RNG seed.
    pub seed: u64,
    /// Velocity cap for every solver, as a fraction of each dimension's range; `None` keeps
    /// each solver's own.
    pub velocity_cap: Option<f64>,
}

impl SolverSettings {
    /// A single-population run of `particles` particles (the multi-population sizes are
    /// Zhi & Zuo 2024, Table 5's, on one thread).
    pub fn single(particles: usize, seed: u64, velocity_cap: Option<f64>) -> SolverSettings {
        let amp = MultiPso::amp(seed);
        SolverSettings {
            particles,
            multi: MultiSizes {
                populations: amp.populations,
                particles: amp.particles,
                leader_particles: amp.leader_particles,
                exchange_every: amp.exchange_every,
            },
            threads: 1,
            seed,
            velocity_cap,
        }
    }
}

/// What to do with the solver an algorithm names. The method is generic over the solver, so
/// the visitor runs it exactly as if it had built it itself.
pub trait SolverVisitor<P: Problem> {
    /// What the visit gives back (a run's result, typically).
    type Output;
    /// Takes the configured solver.
    fn visit<S: Solver<P>>(self, solver: S) -> Self::Output;
}

/// Builds the solver `algorithm` names with `settings` and hands it to `visitor`. Each arm is
/// the solver's preset from its paper with the settings' sizes, seed and cap.
pub fn with_solver<P: Problem, V: SolverVisitor<P>>(
    algorithm: Algorithm,
    settings: &SolverSettings,
    visitor: V,
) -> V::Output {
    let (m, seed, cap) = (settings.particles, settings.seed, settings.velocity_cap);
    match algorithm {
        Algorithm::AmpPso | Algorithm::MpPso => visitor.visit(multi(algorithm, settings)),
        Algorithm::Pso => visitor.visit(Pso::classic(m, seed).capped(cap)),
        Algorithm::APso => visitor.visit(Pso::adaptive(m, seed).capped(cap)),
        Algorithm::Ipso => visitor.visit(Ipso::table8(m, seed).capped(cap)),
        Algorithm::Spso => visitor.visit(Pso::spso(m, seed).capped(cap)),
        Algorithm::Cbpso => visitor.visit(Cbpso::table8(m, seed).capped(cap)),
        Algorithm::Nspso => visitor.visit(Nspso::table8(m, seed).capped(cap)),
        Algorithm::AcoPso => visitor.visit(AcoPso::table8(m, seed).capped(cap)),
        Algorithm::EpaPso => visitor.visit(EpaPso::table2(m, seed).capped(cap)),
        Algorithm::PsoLength | Algorithm::MPso => visitor.visit(baseline_pso(m, seed).capped(cap)),
        Algorithm::DePso => visitor.visit(DePso::table5(m, seed).capped(cap)),
        Algorithm::LdiwPso => visitor.visit(LdiwPso::table5(m, seed).capped(cap)),
        Algorithm::Lcpso => visitor.visit(Lcpso::table5(m, seed).capped(cap)),
        Algorithm::CfPso => visitor.visit(CfPso::clerc_kennedy(m, seed).capped(cap)),
    }
}

/// AMP-PSO or MP-PSO with the settings' sizes; Zhi & Zuo's cap unless the settings set one.
fn multi(algorithm: Algorithm, s: &SolverSettings) -> MultiPso {
    MultiPso {
        populations: s.multi.populations,
        particles: s.multi.particles,
        leader_particles: s.multi.leader_particles,
        exchange_every: s.multi.exchange_every,
        schedule: schedule(algorithm),
        max_velocity_fraction: s.velocity_cap.unwrap_or(AMP_PSO_VELOCITY_CAP),
        threads: s.threads,
        seed: s.seed,
    }
}

/// The PSO both of Zhang et al.'s baselines use: Clerc and Kennedy's constricted coefficients
/// (ω = 0.729, c1 = c2 = 1.494), the usual "plain PSO" — Zhang et al. 2022 does not list its baseline's
/// settings.
pub fn baseline_pso(particles: usize, seed: u64) -> Pso {
    Pso {
        particles,
        schedule: Schedule::Fixed(Coefficients {
            w: 0.729,
            c1: 1.494,
            c2: 1.494,
            c3: 0.0,
        }),
        max_velocity_fraction: 0.2,
        seed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::{Executor, SolverState};
    use crate::swarm::testfns::ShiftedSphere;

    /// Runs the visited solver for a few iterations and keeps its convergence curve.
    struct Curve<'a>(&'a ShiftedSphere);

    impl SolverVisitor<ShiftedSphere> for Curve<'_> {
        type Output = (Vec<f64>, u64);
        fn visit<S: Solver<ShiftedSphere>>(self, mut solver: S) -> (Vec<f64>, u64) {
            let out = Executor::new(5).run(self.0, &mut solver, |_| {});
            (out.convergence, out.state.evaluations())
        }
    }

    #[test]
    fn every_algorithm_has_a_solver_and_a_family_that_agree() {
        let problem = ShiftedSphere::new(3);
        let s = SolverSettings::single(6, 3, None);
        for a in Algorithm::ALL {
            let (curve, evaluations) = with_solver(a, &s, Curve(&problem));
            assert_eq!(curve.len(), 5, "{a:?}");
            assert!(evaluations > 0, "{a:?}");
            assert_eq!(leg_algorithm(a).map(LegAlgorithm::algorithm), {
                matches!(family(a), Family::Tour(_)).then_some(a)
            });
        }
    }

    #[test]
    fn the_catalog_builds_the_presets_it_names() {
        let problem = ShiftedSphere::new(3);
        let s = SolverSettings::single(8, 5, Some(0.3));
        let direct = Curve(&problem).visit(Ipso::table8(8, 5).capped(Some(0.3)));
        assert_eq!(with_solver(Algorithm::Ipso, &s, Curve(&problem)), direct);
        let direct = Curve(&problem).visit(MultiPso::amp(5).capped(Some(0.3)));
        let amp = SolverSettings {
            threads: 2,
            ..SolverSettings::single(8, 5, Some(0.3))
        };
        assert_eq!(
            with_solver(Algorithm::AmpPso, &amp, Curve(&problem)),
            direct
        );
    }

    #[test]
    fn leg_algorithms_are_the_tour_planners() {
        assert_eq!(leg_algorithm(Algorithm::DePso), Some(LegAlgorithm::DePso));
        assert_eq!(leg_algorithm(Algorithm::Lcpso), Some(LegAlgorithm::Lcpso));
        assert_eq!(leg_algorithm(Algorithm::AmpPso), None);
        assert_eq!(LegAlgorithm::LdiwPso.name(), "ldiw-pso");
        assert_eq!(schedule(Algorithm::MpPso), Schedule::TABLE5_FIXED);
    }
}
