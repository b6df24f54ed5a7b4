//! Ocean currents behind one trait, so the analytic field of Zhang et al. 2022 can be replaced by a real
//! forecast without touching the cost: the energy terms only ever ask for the current at a point.
//!
//! Shoal's z is up and `bounds.max[2]` is the sea surface, so the depth of a point is
//! `surface_z − z`.

use crate::geometry::Vec3;

/// A current field: water velocity (m/s, east/north/up) at a point.
pub trait CurrentField: Send + Sync + std::fmt::Debug {
    /// Current velocity at `p`, m/s.
    fn velocity(&self, p: &Vec3) -> Vec3;
}

/// Zhang et al. 2022, eq. (2): a horizontal current whose strength falls linearly with depth,
/// `u_c = u_s (ζ_bd − ζ) / ζ_bd`, `v_c = v_s (ζ_bd − ζ) / ζ_bd`, `w_c = 0`, where ζ is the depth
/// and ζ_bd the map's greatest depth. The paper fixes `u_s = v_s = −1.0` m/s; a scenario may pick
/// another surface velocity.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthDecayCurrent {
    /// `(u_s, v_s)`: the current at the surface, m/s.
    pub surface_mps: [f64; 2],
    /// z of the sea surface, metres.
    pub surface_z: f64,
    /// ζ_bd: the map's greatest depth, metres (> 0); the current is zero there and below.
    pub max_depth_m: f64,
}

impl DepthDecayCurrent {
    /// `(ζ_bd − ζ) / ζ_bd` with the depth clamped into `[0, ζ_bd]`: 1 at the surface, 0 at the
    /// bottom of the map.
    pub fn strength(&self, z: f64) -> f64 {
        if self.max_depth_m <= 0.0 || !z.is_finite() {
            return 0.0;
        }
        let depth = (self.surface_z - z).clamp(0.0, self.max_depth_m);
        (self.max_depth_m - depth) / self.max_depth_m
    }
}

impl CurrentField for DepthDecayCurrent {
    fn velocity(&self, p: &Vec3) -> Vec3 {
        let s = self.strength(p.z);
        Vec3::new(self.surface_mps[0] * s, self.surface_mps[1] * s, 0.0)
    }
}

/// Still water: the field of a scenario without currents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StillWater;

impl CurrentField for StillWater {
    fn velocity(&self, _p: &Vec3) -> Vec3 {
        Vec3::zeros()
    }
}

/// Zhang et al. 2022, eq. (3): the velocity over ground is the vehicle's velocity through the water plus
/// the current. Shoal plans ground tracks, so the planner goes the other way round: the water
/// velocity the vehicle must hold to make `ground` over ground is `ground − current`.
pub fn water_velocity(ground: &Vec3, current: &Vec3) -> Vec3 {
    ground - current
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn paper_field() -> DepthDecayCurrent {
        DepthDecayCurrent {
            surface_mps: [-1.0, -1.0],
            surface_z: 100.0,
            max_depth_m: 100.0,
        }
    }

    #[test]
    fn strength_falls_linearly_with_depth() {
        let c = paper_field();
        // Surface: the full −1 m/s on both axes; 25 m deep: 0.75; at the bottom and below it: 0.
        assert_abs_diff_eq!(
            c.velocity(&Vec3::new(0., 0., 100.)),
            Vec3::new(-1., -1., 0.)
        );
        assert_abs_diff_eq!(
            c.velocity(&Vec3::new(5., 5., 75.)),
            Vec3::new(-0.75, -0.75, 0.),
            epsilon = 1e-12
        );
        assert_abs_diff_eq!(c.velocity(&Vec3::new(0., 0., 0.)), Vec3::zeros());
        assert_abs_diff_eq!(c.velocity(&Vec3::new(0., 0., -10.)), Vec3::zeros());
        // Above the surface (a point out of the water) is clamped to the surface value.
        assert_abs_diff_eq!(c.strength(120.0), 1.0);
    }

    #[test]
    fn water_velocity_is_ground_minus_current() {
        // Heading east at 2 m/s over ground into a 0.5 m/s westward current: 2.5 m/s through
        // the water.
        let w = water_velocity(&Vec3::new(2., 0., 0.), &Vec3::new(-0.5, 0., 0.));
        assert_abs_diff_eq!(w, Vec3::new(2.5, 0., 0.));
        assert_abs_diff_eq!(StillWater.velocity(&Vec3::new(1., 2., 3.)), Vec3::zeros());
    }
}
