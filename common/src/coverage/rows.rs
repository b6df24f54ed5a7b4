//! The rows of a Boustrophedon area and which stretches of them have been driven.
//!
//! A row's free stretches are its span `[x_lo, x_hi]` minus the x-ranges of the no-go boxes
//! crossing its centre line. A stretch counts as covered once half of it has been driven along
//! the row: a sweep that lands in a covered stretch stops (it has reached rows an earlier sweep
//! drove), and the planner sends the vehicle on to the first stretch no sweep has covered yet.

use super::boxes::Rect;

/// Shortest stretch worth a sweep of its own: four turning radii (20 m at `R_min` = 5 m). A
/// transit enters a stretch `R_min` from its end (it has to turn into the row clear of the box
/// that ends it), so a shorter stretch leaves almost nothing to drive.
fn min_stretch(r_min: f64) -> f64 {
    4.0 * r_min
}

/// Rows, their free stretches, and what has been driven.
#[derive(Debug, Clone)]
pub struct RowBook {
    /// Row centre lines, south to north.
    ys: Vec<f64>,
    /// Row span (the U-turn space lies outside it).
    x_range: (f64, f64),
    /// Free stretches per row, west to east.
    free: Vec<Vec<(f64, f64)>>,
    /// Driven length per stretch.
    driven: Vec<Vec<f64>>,
    /// Stretches given up on (no transit reached them).
    abandoned: Vec<Vec<bool>>,
    /// Every drive booked, `(row, a, b)`, in order.
    drives: Vec<(usize, f64, f64)>,
    /// Shortest stretch worth a sweep, metres.
    min_len: f64,
}

impl RowBook {
    /// The book of rows `ys` spanning `x_range`, cut by `boxes`.
    pub fn new(ys: Vec<f64>, x_range: (f64, f64), boxes: &[Rect], r_min: f64) -> Self {
        let (x_lo, x_hi) = x_range;
        let free: Vec<Vec<(f64, f64)>> = ys
            .iter()
            .map(|&y| {
                let mut cuts: Vec<(f64, f64)> = boxes
                    .iter()
                    .filter(|b| b.y0 < y && y < b.y1)
                    .map(|b| (b.x0, b.x1))
                    .collect();
                cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
                let mut out = Vec::new();
                let mut x = x_lo;
                for (a, b) in cuts {
                    if a > x {
                        out.push((x, a.min(x_hi)));
                    }
                    x = x.max(b);
                    if x >= x_hi {
                        break;
                    }
                }
                if x < x_hi {
                    out.push((x, x_hi));
                }
                out.retain(|(a, b)| b > a);
                out
            })
            .collect();
        let driven = free.iter().map(|f| vec![0.0; f.len()]).collect();
        let abandoned = free.iter().map(|f| vec![false; f.len()]).collect();
        Self {
            ys,
            x_range,
            free,
            driven,
            abandoned,
            drives: Vec::new(),
            min_len: min_stretch(r_min),
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.ys.len()
    }

    /// Centre line of row `k`.
    pub fn y(&self, k: usize) -> f64 {
        self.ys.get(k).copied().unwrap_or(f64::NAN)
    }

    /// The rows' span.
    pub fn x_range(&self) -> (f64, f64) {
        self.x_range
    }

    /// The free stretches of row `k`.
    pub fn stretches(&self, k: usize) -> &[(f64, f64)] {
        self.free.get(k).map_or(&[], |v| v.as_slice())
    }

    /// Books a drive along row `k` from `a` to `b` (either order).
    pub fn drive(&mut self, k: usize, a: f64, b: f64) {
        let (lo, hi) = (a.min(b), a.max(b));
        self.drives.push((k, lo, hi));
        if let (Some(free), Some(driven)) = (self.free.get(k), self.driven.get_mut(k)) {
            for (s, d) in free.iter().zip(driven.iter_mut()) {
                *d += (hi.min(s.1) - lo.max(s.0)).max(0.0);
            }
        }
    }

    /// Every drive booked so far, `(row, x_lo, x_hi)`: another book of the same rows (cut by
    /// other boxes) replays them to know what is already driven.
    pub fn drives(&self) -> &[(usize, f64, f64)] {
        &self.drives
    }

    /// Whether the stretch of row `k` holding `x` is covered (or `x` is in no stretch).
    pub fn is_done(&self, k: usize, x: f64) -> bool {
        self.stretches(k)
            .iter()
            .position(|s| s.0 - 1e-9 <= x && x <= s.1 + 1e-9)
            .is_none_or(|i| self.stretch_done(k, i))
    }

    /// Whether stretch `i` of row `k` is covered, too short to matter, or abandoned.
    pub fn stretch_done(&self, k: usize, i: usize) -> bool {
        let Some(&(a, b)) = self.free.get(k).and_then(|f| f.get(i)) else {
            return true;
        };
        let driven = self
            .driven
            .get(k)
            .and_then(|d| d.get(i))
            .copied()
            .unwrap_or(0.0);
        let abandoned = self
            .abandoned
            .get(k)
            .and_then(|d| d.get(i))
            .copied()
            .unwrap_or(true);
        b - a < self.min_len || driven >= 0.5 * (b - a) || abandoned
    }

    /// Gives up on the stretch of row `k` holding `x` (if any).
    pub fn abandon_at(&mut self, k: usize, x: f64) {
        if let Some(i) = self
            .stretches(k)
            .iter()
            .position(|s| s.0 - 1e-9 <= x && x <= s.1 + 1e-9)
        {
            self.abandon(k, i);
        }
    }

    /// Gives up on stretch `i` of row `k`.
    pub fn abandon(&mut self, k: usize, i: usize) {
        if let Some(flag) = self.abandoned.get_mut(k).and_then(|f| f.get_mut(i)) {
            *flag = true;
        }
    }

    /// Every open stretch `(row, index, [x_a, x_b])`, south to north then west to east.
    pub fn open_stretches(&self) -> Vec<(usize, usize, [f64; 2])> {
        (0..self.rows())
            .flat_map(|k| {
                self.stretches(k)
                    .iter()
                    .enumerate()
                    .filter(move |&(i, _)| !self.stretch_done(k, i))
                    .map(move |(i, s)| (k, i, [s.0, s.1]))
            })
            .collect()
    }

    /// The first open stretch, south to north then west to east.
    pub fn next_open(&self) -> Option<(usize, usize)> {
        (0..self.rows()).find_map(|k| {
            (0..self.stretches(k).len())
                .find(|&i| !self.stretch_done(k, i))
                .map(|i| (k, i))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_cut_rows_into_stretches_and_half_a_drive_covers_one() {
        let boxes = [
            Rect::new(30.0, 5.0, 50.0, 25.0),
            Rect::new(45.0, 15.0, 60.0, 40.0),
        ];
        let mut book = RowBook::new(vec![0.0, 10.0, 20.0, 30.0], (5.0, 95.0), &boxes, 1.0);
        assert_eq!(book.stretches(0), &[(5.0, 95.0)]);
        assert_eq!(book.stretches(1), &[(5.0, 30.0), (50.0, 95.0)]);
        assert_eq!(book.stretches(2), &[(5.0, 30.0), (60.0, 95.0)]);
        assert_eq!(book.stretches(3), &[(5.0, 45.0), (60.0, 95.0)]);
        assert_eq!(book.next_open(), Some((0, 0)));
        book.drive(0, 95.0, 51.0);
        assert!(!book.is_done(0, 10.0));
        book.drive(0, 51.0, 40.0);
        assert!(book.is_done(0, 10.0));
        assert_eq!(book.next_open(), Some((1, 0)));
        // Inside a box counts as done: nothing to land on there.
        assert!(book.is_done(1, 40.0));
        book.abandon(1, 0);
        assert_eq!(book.next_open(), Some((1, 1)));
    }
}
