//! Spherical net cages and their inspection points (Hu et al. 2023, §II, Table 4).
//!
//! Units: Table 4 prints bare numbers (centres around 100–600, radii 45–80) with no unit; the
//! simulation is an abstract MATLAB space. Shoal reads one table unit as one metre, so the
//! conversion is the identity, and keeps the table's axes as Shoal's frame (x east, y north,
//! z up, origin at the corner of the scenario box).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use crate::geometry::Vec3;

/// A spherical net cage, treated as a spherical obstacle (§II, eq. (29)).
#[derive(Debug, Clone, PartialEq)]
pub struct Cage {
    /// Table 4's code, e.g. "A1".
    pub id: String,
    /// Centre, metres.
    pub centre: Vec3,
    /// Radius R of the cage sphere, metres.
    pub radius_m: f64,
}

impl Cage {
    /// A cage named `id` at `(x, y, z)` with radius `r` (metres).
    pub fn new(id: &str, x: f64, y: f64, z: f64, r: f64) -> Cage {
        Cage {
            id: id.to_string(),
            centre: Vec3::new(x, y, z),
            radius_m: r,
        }
    }
}

/// Cage group A of Hu et al. 2023, Table 4 (one table unit = one metre).
pub fn cage_group_a() -> Vec<Cage> {
    vec![
        Cage::new("A1", 300.0, 400.0, 460.0, 50.0),
        Cage::new("A2", 100.0, 150.0, 150.0, 45.0),
        Cage::new("A3", 600.0, 522.0, 510.0, 50.0),
        Cage::new("A4", 350.0, 200.0, 440.0, 80.0),
        Cage::new("A5", 150.0, 250.0, 300.0, 70.0),
    ]
}

/// Cage group B of Hu et al. 2023, Table 4: group A's centres with other radii.
pub fn cage_group_b() -> Vec<Cage> {
    vec![
        Cage::new("B1", 300.0, 400.0, 460.0, 75.0),
        Cage::new("B2", 100.0, 150.0, 150.0, 50.0),
        Cage::new("B3", 600.0, 522.0, 510.0, 51.0),
        Cage::new("B4", 350.0, 200.0, 440.0, 80.0),
        Cage::new("B5", 150.0, 250.0, 300.0, 61.0),
    ]
}

/// The AUV's departure and return point ("point G" of Fig. 18/19). The seed gives no
/// coordinates; Shoal uses the corner of the box, the origin.
pub fn paper_base() -> Vec3 {
    Vec3::zeros()
}

/// The planning box `ABCD–EFGH` of Fig. 12. The seed gives no size; `[0, 700]³` m holds every
/// cage of both groups (largest reach: A3/B3 at 600 + 51 in x, 510 + 51 in z) with room to go
/// around them.
pub fn paper_bounds() -> (Vec3, Vec3) {
    (Vec3::zeros(), Vec3::new(700.0, 700.0, 700.0))
}

/// How far outside the cage sphere the monitoring sphere lies, metres. §II only says "slightly
/// greater than R"; 5 m is 6–11 % of Table 4's radii.
pub const MONITOR_STANDOFF_M: f64 = 5.0;

/// A point an AUV must visit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InspectionPoint {
    /// Index of the cage it monitors.
    pub cage: usize,
    /// Where it is, metres.
    pub position: Vec3,
}

/// How the first inspection point of each cage is placed on the horizontal circle of the
/// monitoring sphere (the second is always its mirror through the centre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FirstPoint {
    /// Hu et al. 2023, §II: "a monitoring point was randomly selected" — a uniform azimuth per cage from
    /// this seed.
    Random {
        /// RNG seed.
        seed: u64,
    },
    /// Facing a point (usually the base): the horizontal direction from the centre towards it;
    /// +x when the point is straight above or below the centre.
    Toward(Vec3),
    /// A fixed azimuth, radians from +x towards +y.
    Azimuth(f64),
}

/// Two inspection points per cage (Hu et al. 2023, §II): on the horizontal plane through the centre, at
/// distance `R + standoff_m` from it, the second the mirror of the first through the centre.
/// The points of cage `k` are entries `2k` and `2k + 1`.
///
/// Why a plane through the centre: there the monitoring circle is largest, so the two points
/// look at opposite sides of the cage.
pub fn inspection_points(
    cages: &[Cage],
    standoff_m: f64,
    first: FirstPoint,
) -> Vec<InspectionPoint> {
    let mut rng = match first {
        FirstPoint::Random { seed } => Some(StdRng::seed_from_u64(seed)),
        _ => None,
    };
    let mut points = Vec::with_capacity(2 * cages.len());
    for (k, cage) in cages.iter().enumerate() {
        let azimuth = match (first, rng.as_mut()) {
            (_, Some(rng)) => rng.random_range(0.0..std::f64::consts::TAU),
            (FirstPoint::Toward(t), None) => {
                let (dx, dy) = (t.x - cage.centre.x, t.y - cage.centre.y);
                if dx.hypot(dy) <= 1e-9 {
                    0.0
                } else {
                    dy.atan2(dx)
                }
            }
            (FirstPoint::Azimuth(a), None) => a,
            (FirstPoint::Random { .. }, None) => 0.0,
        };
        let r = cage.radius_m + standoff_m;
        let offset = Vec3::new(r * azimuth.cos(), r * azimuth.sin(), 0.0);
        points.push(InspectionPoint {
            cage: k,
            position: cage.centre + offset,
        });
        points.push(InspectionPoint {
            cage: k,
            position: cage.centre - offset,
        });
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn table_4_groups_share_centres_and_differ_in_radius() {
        let (a, b) = (cage_group_a(), cage_group_b());
        assert_eq!((a.len(), b.len()), (5, 5));
        for (ca, cb) in a.iter().zip(&b) {
            assert_eq!(ca.centre, cb.centre);
        }
        let radii: Vec<f64> = b.iter().map(|c| c.radius_m).collect();
        assert_eq!(radii, vec![75.0, 50.0, 51.0, 80.0, 61.0]);
        assert_eq!(a[3].centre, Vec3::new(350.0, 200.0, 440.0));
        // Every cage fits in the box.
        let (lo, hi) = paper_bounds();
        for c in a.iter().chain(&b) {
            for d in 0..3 {
                assert!(c.centre[d] - c.radius_m > lo[d] && c.centre[d] + c.radius_m < hi[d]);
            }
        }
    }

    #[test]
    fn inspection_points_are_mirrored_on_the_centre_plane() {
        let cages = vec![Cage::new("X", 100.0, 100.0, 50.0, 10.0)];
        // Facing the base at the origin: direction (−1, −1)/√2, distance 15.
        let p = inspection_points(&cages, 5.0, FirstPoint::Toward(Vec3::zeros()));
        assert_eq!(p.len(), 2);
        let h = 15.0 / 2f64.sqrt();
        assert_abs_diff_eq!(
            p[0].position,
            Vec3::new(100.0 - h, 100.0 - h, 50.0),
            epsilon = 1e-9
        );
        assert_abs_diff_eq!(
            p[1].position,
            Vec3::new(100.0 + h, 100.0 + h, 50.0),
            epsilon = 1e-9
        );
        // Along +x.
        let p = inspection_points(&cages, 5.0, FirstPoint::Azimuth(0.0));
        assert_abs_diff_eq!(
            p[0].position,
            Vec3::new(115.0, 100.0, 50.0),
            epsilon = 1e-12
        );
        assert_abs_diff_eq!(p[1].position, Vec3::new(85.0, 100.0, 50.0), epsilon = 1e-12);
        // Random azimuths: reproducible, on the circle, mirrored.
        let a = inspection_points(&cage_group_a(), 5.0, FirstPoint::Random { seed: 3 });
        let b = inspection_points(&cage_group_a(), 5.0, FirstPoint::Random { seed: 3 });
        assert_eq!(a, b);
        for (k, c) in cage_group_a().iter().enumerate() {
            let (p, q) = (a[2 * k], a[2 * k + 1]);
            assert_eq!((p.cage, q.cage), (k, k));
            assert_abs_diff_eq!(
                (p.position - c.centre).norm(),
                c.radius_m + 5.0,
                epsilon = 1e-9
            );
            assert_abs_diff_eq!(p.position + q.position, 2.0 * c.centre, epsilon = 1e-9);
            assert_abs_diff_eq!(p.position.z, c.centre.z, epsilon = 1e-12);
        }
    }
}
