//! Proptest strategies shared by the unit tests of several modules (apart from [`crate::fixtures`],
//! which builds on the cost model: these build only trajectories, so the cost model's own tests
//! can use them).

/// A vehicle crossing a 1 km box in 2–5 straight legs at 0.5–2.5 m/s,
/// from t = 0.
pub fn crossing() -> impl proptest::strategy::Strategy<Value = crate::trajectory::Trajectory> {
    use proptest::prelude::*;
    prop::collection::vec(
        ((0.0..1000.0f64, 0.0..1000.0f64, 0.0..300.0f64), 0.5..2.5f64),
        3..7,
    )
    .prop_map(|samples| {
        let mut t = 0.0;
        let mut out = crate::trajectory::Trajectory {
            times: Vec::new(),
            points: Vec::new(),
        };
        for ((x, y, z), speed) in samples {
            let p = crate::geometry::Vec3::new(x, y, z);
            if let Some(q) = out.points.last() {
                t += (p - q).norm() / speed;
            }
            out.times.push(t);
            out.points.push(p);
        }
        out
    })
}
