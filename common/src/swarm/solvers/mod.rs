//! One file per optimizer, each over the shared [`Solver`](super::core::Solver) trait of
//! [`core`](super::core) and citing the paper (and equations) it implements. Which scenario
//! name runs which solver, with which settings, is decided in [`catalog`](super::catalog) alone.

pub mod acopso;
pub mod cbpso;
pub mod cfpso;
pub mod depso;
pub mod epapso;
pub mod ipso;
pub mod lcpso;
pub mod ldiwpso;
pub mod multi;
pub mod nspso;
pub mod pso;
