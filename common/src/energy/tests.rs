//! Hand-computed checks of every Zhang et al. 2022 cost term.

use std::sync::Arc;

use approx::assert_abs_diff_eq;

use super::*;
use crate::current::{DepthDecayCurrent, StillWater};
use crate::terrain::Mountain;

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn still(speed: f64) -> EnergyModel {
    EnergyModel {
        terrain: None,
        terrain_clearance_m: 2.0,
        current: Arc::new(StillWater),
        ground_speed_mps: speed,
        min_turn_radius_m: 8.0,
        pitch_range_deg: (-20.0, 20.0),
        weights: Weights::default(),
    }
}

#[test]
fn resistance_of_eq_4() {
    assert_abs_diff_eq!(resistance(0.0), 5.3);
    // 0.0783·400 − 0.0753·20 + 5.3 = 31.32 − 1.506 + 5.3
    assert_abs_diff_eq!(resistance(20.0), 35.114, epsilon = 1e-12);
    // 0.0783·100 + 0.753 + 5.3
    assert_abs_diff_eq!(resistance(-10.0), 13.883, epsilon = 1e-12);
}

#[test]
fn turn_radius_of_three_points() {
    assert_abs_diff_eq!(
        turn_radius(&v(1., 0., 0.), &v(0., 1., 0.), &v(-1., 0., 0.)),
        1.0,
        epsilon = 1e-12
    );
    // A right angle with 10 m arms: the hypotenuse 10√2 is a diameter.
    assert_abs_diff_eq!(
        turn_radius(&v(0., 0., 0.), &v(10., 0., 0.), &v(10., 10., 0.)),
        5.0 * 2f64.sqrt(),
        epsilon = 1e-12
    );
    assert!(turn_radius(&v(0., 0., 0.), &v(1., 1., 1.), &v(2., 2., 2.)).is_infinite());
    assert!(turn_radius(&v(0., 0., 0.), &v(0., 0., 0.), &v(2., 2., 2.)).is_infinite());
}

#[test]
fn heading_factor_and_weights() {
    assert_abs_diff_eq!(heading_factor(-0.5), 0.5f64.exp());
    assert_abs_diff_eq!(heading_factor(0.5), (-0.5f64).exp());
    // Equal costs: cos(π/2) = 0, the initial weight; the next cost twice the mean: cos(π) = −1.
    assert_abs_diff_eq!(adjusted_weight(0.25, 0.01, 0.5, 1.0), 0.25, epsilon = 1e-15);
    assert_abs_diff_eq!(adjusted_weight(0.25, 0.01, 0.5, 2.0), 0.26, epsilon = 1e-15);
    assert_abs_diff_eq!(adjusted_weight(0.25, 0.01, 0.5, 0.0), 0.24, epsilon = 1e-15);
}

#[test]
fn a_right_angle_in_still_water() {
    // 20 m at 2 m/s, level: X = 5.3 N through the water at 2 m/s for 10 s = 106 J; no current,
    // no q_ea. The corner turns on a 5√2 m circle, under R_AUV = 8 m.
    let m = still(2.0);
    let (t, pieces) = m.terms(&[v(0., 0., 0.), v(10., 0., 0.), v(10., 10., 0.)]);
    assert_abs_diff_eq!(t.q_path, 20.0);
    assert_abs_diff_eq!(t.q_et, 106.0, epsilon = 1e-9);
    assert_abs_diff_eq!(t.q_ea, 0.0);
    assert_abs_diff_eq!(t.q_e, 106.0, epsilon = 1e-9);
    assert_abs_diff_eq!(t.q_r, 0.8629150101523956, epsilon = 1e-12);
    assert_abs_diff_eq!(t.q_a, 0.0);
    assert_abs_diff_eq!(t.duration_s, 10.0, epsilon = 1e-12);
    assert_abs_diff_eq!(
        t.f_f,
        (20.0 + 106.0 + 0.8629150101523956) / 4.0,
        epsilon = 1e-9
    );
    assert_eq!(pieces.radius.len(), 2);
    assert_abs_diff_eq!(pieces.radius[0], 0.8629150101523956, epsilon = 1e-12);
}

#[test]
fn pitch_beyond_the_range_is_squared() {
    // 45° up: (45 − 20)² = 625 deg²; 45° down: (−45 + 20)² = 625 more.
    let m = still(1.0);
    let (t, _) = m.terms(&[v(0., 0., 0.), v(10., 0., 10.), v(20., 0., 0.)]);
    assert_abs_diff_eq!(t.q_a, 1250.0, epsilon = 1e-9);
    assert_abs_diff_eq!(t.max_pitch_deg, 45.0, epsilon = 1e-9);
    assert_abs_diff_eq!(t.min_pitch_deg, -45.0, epsilon = 1e-9);
}

#[test]
fn energy_against_a_current() {
    // 10 m east at 50 m depth of 100: the current is (−0.5, −0.5, 0), so the vehicle holds
    // (2.5, 0.5, 0) through the water, |V_AUV| = √6.5, for 5 s. cos θ_uc = −1.5 / (√6.5 · √0.5).
    let m = EnergyModel {
        current: Arc::new(DepthDecayCurrent {
            surface_mps: [-1.0, -1.0],
            surface_z: 100.0,
            max_depth_m: 100.0,
        }),
        ..still(2.0)
    };
    let (t, _) = m.terms(&[v(0., 0., 50.), v(10., 0., 50.)]);
    assert_abs_diff_eq!(t.q_et, 67.5620085551044, epsilon = 1e-9);
    assert_abs_diff_eq!(t.q_ea, 35.82905107904079, epsilon = 1e-9);
    assert_abs_diff_eq!(t.max_water_speed_mps, 6.5f64.sqrt(), epsilon = 1e-12);
    // Going the other way (with the current) is cheaper on both terms.
    let (back, _) = m.terms(&[v(10., 0., 50.), v(0., 0., 50.)]);
    assert!(back.q_et < t.q_et && back.q_ea < t.q_ea);
}

#[test]
fn seabed_clearance() {
    // A 10 m hill at the origin: 11 m above it with a 2 m clearance is 1 m short.
    let m = EnergyModel {
        terrain: Some(Terrain::Hills(vec![Mountain {
            centre: [0.0, 0.0],
            height_m: 10.0,
            spread_m: [5.0, 5.0],
        }])),
        ..still(1.0)
    };
    let (t, _) = m.terms(&[v(0., 0., 11.), v(50., 0., 11.)]);
    assert_eq!(t.terrain_violations, 1);
    assert_abs_diff_eq!(t.terrain_margin_m, -1.0, epsilon = 1e-12);
}

#[test]
fn segment_weights_follow_the_next_segment() {
    let m = still(1.0);
    let pieces = Pieces {
        lengths: vec![1.0, 3.0],
        energies: vec![2.0, 2.0],
        radius: vec![0.0, 0.0],
        angle: vec![0.0, 1.0],
    };
    let k0 = m.segment_weights(&pieces, 0);
    // Length 1 → 3: ratio 3 / 2 = 1.5, K = 0.25 − cos(0.75 π)·0.01.
    assert_abs_diff_eq!(k0[0], 0.25707106781186545, epsilon = 1e-12);
    // Equal energies: 0.25. Radius unchanged: difference 0, cos 0 = 1: 0.24.
    assert_abs_diff_eq!(k0[1], 0.25, epsilon = 1e-12);
    assert_abs_diff_eq!(k0[2], 0.24, epsilon = 1e-12);
    // Angle cost 0 → 1: cos(π/2) = 0: 0.25.
    assert_abs_diff_eq!(k0[3], 0.25, epsilon = 1e-12);
    // The last segment compares with itself.
    let k1 = m.segment_weights(&pieces, 1);
    assert_abs_diff_eq!(k1[0], 0.25, epsilon = 1e-12);
    // Weighted sum with unit scales: segment 0 has length 1, energy 2; segment 1 length 3,
    // energy 2 and angle 1.
    let expect = k0[0] * 1.0 + k0[1] * 2.0 + k1[0] * 3.0 + k1[1] * 2.0 + k1[3] * 1.0;
    assert_abs_diff_eq!(m.weighted(&pieces, [1.0; 4]), expect, epsilon = 1e-12);
}
