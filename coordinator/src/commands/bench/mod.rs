//! The benchmark commands: the papers' tables re-run (`bench-functions`, `bench-energy`,
//! `bench-cages`, `bench-coverage`), the coordinator's own load (`bench-telemetry`) and how
//! planning scales with the fleet (`bench-scale`); [`pool`]
//! runs their independent jobs on worker threads.

pub mod cages;
pub mod coverage;
pub mod energy;
pub mod functions;
pub mod headless;
pub mod pool;
pub mod scale;
pub mod telemetry;
