//! The sampled reference path: windowed monotone projection (progress and signed cross-track
//! error, CPP-DSMV, §3 Figure 7(c)) and look-ups by arc length for the MPC horizon.

use super::types::{wrap_angle, PathSample, TrackingError};

/// A checked, read-only view of the reference samples.
#[derive(Debug, Clone, Copy)]
pub struct Reference<'a> {
    samples: &'a [PathSample],
}

/// Where a point projects on the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Segment index (between samples `seg` and `seg + 1`).
    pub seg: usize,
    /// Arc length of the foot point, m (may pass the ends on the end segments).
    pub s: f64,
    /// Signed perpendicular distance, m, positive to the LEFT of the direction of travel.
    pub lateral: f64,
    /// Reference heading at the foot point, rad.
    pub heading: f64,
    /// Reference curvature of the segment, 1/m.
    pub curvature: f64,
}

/// A reference pose looked up by arc length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefPoint {
    /// East, m.
    pub x: f64,
    /// North, m.
    pub y: f64,
    /// Heading, rad.
    pub heading: f64,
    /// Curvature, 1/m (0 beyond the ends).
    pub curvature: f64,
    /// Segment index used (a hint for the next look-up).
    pub seg: usize,
}

/// Monotone progress along the reference: the last projection's segment and arc length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cursor {
    /// Segment index.
    pub seg: usize,
    /// Arc length, m.
    pub s: f64,
}

impl<'a> Reference<'a> {
    /// Checks the samples: non-empty, finite, arc length non-decreasing.
    pub fn new(samples: &'a [PathSample]) -> Result<Self, TrackingError> {
        if samples.is_empty() {
            return Err(TrackingError::EmptyReference);
        }
        for (i, smp) in samples.iter().enumerate() {
            let finite = [smp.s, smp.x, smp.y, smp.heading, smp.curvature]
                .iter()
                .all(|v| v.is_finite());
            if !finite {
                return Err(TrackingError::InvalidReference {
                    index: i,
                    reason: "non-finite field".to_string(),
                });
            }
            if i > 0 && smp.s < samples[i - 1].s {
                return Err(TrackingError::InvalidReference {
                    index: i,
                    reason: format!(
                        "arc length decreases ({} after {})",
                        smp.s,
                        samples[i - 1].s
                    ),
                });
            }
        }
        Ok(Self { samples })
    }

    /// The samples.
    pub fn samples(&self) -> &'a [PathSample] {
        self.samples
    }

    /// Arc length of the first sample, m.
    pub fn start_s(&self) -> f64 {
        self.samples[0].s
    }

    /// Arc length of the last sample, m.
    pub fn end_s(&self) -> f64 {
        self.samples[self.samples.len() - 1].s
    }

    /// Length, m.
    pub fn length(&self) -> f64 {
        self.end_s() - self.start_s()
    }

    /// A cursor at the start.
    pub fn start_cursor(&self) -> Cursor {
        Cursor {
            seg: 0,
            s: self.start_s(),
        }
    }

    fn n_segments(&self) -> usize {
        self.samples.len().saturating_sub(1)
    }

    /// Projects `(x, y)` onto the segments whose arc-length span meets
    /// `[cursor.s − back, cursor.s + ahead]` and advances the cursor to the nearest foot point.
    /// The window is what keeps progress monotone: with `ahead` below the arc length of a U-turn
    /// the projection never jumps into the next row, however close it is in the plane.
    /// On the first / last segment the foot point may lie beyond the end (infinite line), so the
    /// lateral error stays perpendicular and `s` tells how far the end has been passed.
    pub fn project(
        &self,
        cursor: &mut Cursor,
        x: f64,
        y: f64,
        back: f64,
        ahead: f64,
    ) -> Projection {
        let n_seg = self.n_segments();
        if n_seg == 0 {
            let a = &self.samples[0];
            let (sn, cs) = a.heading.sin_cos();
            let (dx, dy) = (x - a.x, y - a.y);
            return Projection {
                seg: 0,
                s: a.s + dx * cs + dy * sn,
                lateral: cs * dy - sn * dx,
                heading: a.heading,
                curvature: 0.0,
            };
        }
        let lo_s = cursor.s - back;
        let hi_s = cursor.s + ahead;
        let mut first = cursor.seg.min(n_seg - 1);
        while first > 0 && self.samples[first].s > lo_s {
            first -= 1;
        }
        let mut last = cursor.seg.min(n_seg - 1);
        while last + 1 < n_seg && self.samples[last + 1].s < hi_s {
            last += 1;
        }
        let mut best: Option<(f64, usize, f64)> = None;
        for i in first..=last {
            let (a, b) = (&self.samples[i], &self.samples[i + 1]);
            let (ex, ey) = (b.x - a.x, b.y - a.y);
            let len2 = ex * ex + ey * ey;
            let t = if len2 > 1e-18 {
                (((x - a.x) * ex + (y - a.y) * ey) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (qx, qy) = (a.x + t * ex, a.y + t * ey);
            let d2 = (x - qx).powi(2) + (y - qy).powi(2);
            if best.is_none_or(|(bd, _, _)| d2 < bd - 1e-12) {
                best = Some((d2, i, t));
            }
        }
        let (_, seg, t_clamped) = best.unwrap_or((0.0, first, 0.0));
        let (a, b) = (&self.samples[seg], &self.samples[seg + 1]);
        let (ex, ey) = (b.x - a.x, b.y - a.y);
        let len = ex.hypot(ey);
        let (ux, uy) = if len > 1e-9 {
            (ex / len, ey / len)
        } else {
            (a.heading.cos(), a.heading.sin())
        };
        let (dx, dy) = (x - a.x, y - a.y);
        let along = dx * ux + dy * uy;
        let t_free = if len > 1e-9 { along / len } else { 0.0 };
        let beyond_end = seg + 1 == n_seg && t_free > 1.0;
        let before_start = seg == 0 && t_free < 0.0;
        let (t, lateral) = if beyond_end || before_start {
            (t_free, ux * dy - uy * dx)
        } else {
            let (qx, qy) = (a.x + t_clamped * ex, a.y + t_clamped * ey);
            let (px, py) = (x - qx, y - qy);
            let cross = ux * py - uy * px;
            let dist = px.hypot(py);
            (t_clamped, if cross < 0.0 { -dist } else { dist })
        };
        let tc = t.clamp(0.0, 1.0);
        let heading = a.heading + tc * wrap_angle(b.heading - a.heading);
        let proj = Projection {
            seg,
            s: a.s + t * (b.s - a.s),
            lateral,
            heading,
            curvature: b.curvature,
        };
        cursor.seg = seg;
        cursor.s = proj.s;
        proj
    }

    /// The reference pose at arc length `s`, searching forward from segment `hint` (look-ups
    /// along a horizon are in increasing `s`). Beyond the ends the path is extended straight
    /// along the end headings with zero curvature.
    pub fn point_at(&self, s: f64, hint: usize) -> RefPoint {
        let n_seg = self.n_segments();
        let first = &self.samples[0];
        let last = &self.samples[self.samples.len() - 1];
        if n_seg == 0 || s <= first.s {
            let d = if n_seg == 0 {
                s - first.s
            } else {
                (s - first.s).min(0.0)
            };
            let (sn, cs) = first.heading.sin_cos();
            return RefPoint {
                x: first.x + d * cs,
                y: first.y + d * sn,
                heading: first.heading,
                curvature: if d < 0.0 || n_seg == 0 {
                    0.0
                } else {
                    first.curvature
                },
                seg: 0,
            };
        }
        if s >= last.s {
            let d = s - last.s;
            let (sn, cs) = last.heading.sin_cos();
            return RefPoint {
                x: last.x + d * cs,
                y: last.y + d * sn,
                heading: last.heading,
                curvature: if d > 0.0 { 0.0 } else { last.curvature },
                seg: n_seg - 1,
            };
        }
        let mut i = hint.min(n_seg - 1);
        while i > 0 && self.samples[i].s > s {
            i -= 1;
        }
        while i + 1 < n_seg && self.samples[i + 1].s < s {
            i += 1;
        }
        let (a, b) = (&self.samples[i], &self.samples[i + 1]);
        let ds = b.s - a.s;
        let t = if ds > 0.0 { (s - a.s) / ds } else { 0.0 };
        RefPoint {
            x: a.x + t * (b.x - a.x),
            y: a.y + t * (b.y - a.y),
            heading: a.heading + t * wrap_angle(b.heading - a.heading),
            curvature: b.curvature,
            seg: i,
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::types::geometry::{CoveragePath, Piece, PieceKind};
    use super::*;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::PI;

    /// Two rows of `row_len` m along +x then −x, `2r` apart, joined by a left semicircle of
    /// radius r.
    pub(crate) fn two_rows_with_uturn(row_len: f64, r: f64) -> Vec<PathSample> {
        let row1 = Piece::Line {
            from: [0.0, 0.0],
            to: [row_len, 0.0],
        };
        let turn = Piece::turn(row1.end(), r, PI, true);
        let end = turn.end();
        let row2 = Piece::Line {
            from: [end.x, end.y],
            to: [0.0, end.y],
        };
        CoveragePath {
            pieces: vec![
                (PieceKind::Straight, row1),
                (PieceKind::UTurn, turn),
                (PieceKind::Straight, row2),
            ],
        }
        .sample(0.5)
    }

    #[test]
    fn signed_cross_track_is_left_positive() {
        let path = two_rows_with_uturn(50.0, 5.0);
        let r = Reference::new(&path).unwrap_or_else(|e| panic!("{e}"));
        let mut c = r.start_cursor();
        // Row 1 heads east along y = 0: a point at y = +1.5 is on the left. The window reaches
        // 8 m ahead of the cursor, so walk up to it first.
        r.project(&mut c, 5.0, 0.0, 2.0, 8.0);
        let p = r.project(&mut c, 10.3, 1.5, 2.0, 8.0);
        assert_abs_diff_eq!(p.lateral, 1.5, epsilon = 1e-9);
        let p = r.project(&mut c, 11.0, -0.7, 2.0, 8.0);
        assert_abs_diff_eq!(p.lateral, -0.7, epsilon = 1e-9);
        assert_abs_diff_eq!(p.s, 11.0, epsilon = 1e-9);
        assert_abs_diff_eq!(p.heading, 0.0, epsilon = 1e-12);
    }

    #[test]
    fn projection_never_jumps_across_the_uturn() {
        // Rows 10 m apart: at x = 20 on row 1 the point (20, 6) is nearer to row 2 (y = 10)
        // than to row 1, but progress must stay on row 1.
        let path = two_rows_with_uturn(50.0, 5.0);
        let r = Reference::new(&path).unwrap_or_else(|e| panic!("{e}"));
        let mut c = r.start_cursor();
        for k in 0..=20 {
            r.project(&mut c, k as f64, 0.0, 2.0, 8.0);
        }
        let p = r.project(&mut c, 20.5, 6.0, 2.0, 8.0);
        assert!(p.s < 30.0, "jumped to s = {}", p.s);
        assert_abs_diff_eq!(p.lateral, 6.0, epsilon = 1e-9);
    }

    #[test]
    fn progress_follows_the_uturn_and_the_return_row() {
        let path = two_rows_with_uturn(50.0, 5.0);
        let r = Reference::new(&path).unwrap_or_else(|e| panic!("{e}"));
        let mut c = r.start_cursor();
        let mut last_s = f64::NEG_INFINITY;
        for smp in &path {
            // 0.4 m outside the path (to the right).
            let (sn, cs) = smp.heading.sin_cos();
            let p = r.project(&mut c, smp.x + 0.4 * sn, smp.y - 0.4 * cs, 2.0, 8.0);
            assert!(p.s >= last_s - 1e-9);
            last_s = p.s;
            assert!(
                (p.lateral + 0.4).abs() < 0.05,
                "at s = {}: {}",
                smp.s,
                p.lateral
            );
        }
        assert_abs_diff_eq!(last_s, r.end_s(), epsilon = 0.05);
    }

    #[test]
    fn point_at_interpolates_and_extends_past_the_end() {
        let path = two_rows_with_uturn(50.0, 5.0);
        let r = Reference::new(&path).unwrap_or_else(|e| panic!("{e}"));
        let p = r.point_at(25.5, 0);
        assert_abs_diff_eq!(p.x, 25.5, epsilon = 1e-9);
        assert_abs_diff_eq!(p.curvature, 0.0, epsilon = 1e-12);
        let mid_turn = r.point_at(50.0 + 2.5 * std::f64::consts::PI, p.seg);
        assert_abs_diff_eq!(mid_turn.curvature, 0.2, epsilon = 1e-12);
        assert_abs_diff_eq!(mid_turn.x, 55.0, epsilon = 0.05);
        let beyond = r.point_at(r.end_s() + 3.0, mid_turn.seg);
        assert_abs_diff_eq!(beyond.x, -3.0, epsilon = 1e-9);
        assert_abs_diff_eq!(beyond.y, 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(beyond.curvature, 0.0, epsilon = 1e-12);
    }

    #[test]
    fn bad_references_are_rejected() {
        assert_eq!(
            Reference::new(&[]).err(),
            Some(TrackingError::EmptyReference)
        );
        let mut path = two_rows_with_uturn(20.0, 5.0);
        path[3].s = path[1].s;
        assert!(matches!(
            Reference::new(&path).err(),
            Some(TrackingError::InvalidReference { index: 3, .. })
        ));
        let mut path = two_rows_with_uturn(20.0, 5.0);
        path[2].x = f64::NAN;
        assert!(matches!(
            Reference::new(&path).err(),
            Some(TrackingError::InvalidReference { index: 2, .. })
        ));
    }
}
