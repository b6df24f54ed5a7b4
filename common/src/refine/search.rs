//! The Sℓ1QP search of one vehicle's path (Nocedal & Wright 2006, §18.5), against whatever
//! judges it: the whole fleet's fitness when a plan is refined ([`super::refine`]), or one
//! vehicle's cost against fixed others when a replan is ([`super::vehicle`]).

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use super::constraints::{self, Limits, Row};
use super::objective::{model_hessian, objective_gradient};
use super::qp::Program;
use super::settings::RefineSettings;
use crate::broad_phase::{boxes_within, extent, SlabBoxes};
use crate::cost::FleetModel;
use crate::geometry::Vec3;
use crate::trajectory::Trajectory;

/// A timed trajectory as an arena holds it, borrowed: its sample times and positions.
pub(super) type Samples<'e> = (&'e [f64], &'e [Vec3]);

/// What a search steps in: how a position is scored and what the rows see of it.
pub(super) trait Arena {
    /// One scored position.
    type Eval: Clone;
    /// The fleet model (scenario, obstacles, decoding).
    fn model(&self) -> &FleetModel;
    /// Scores position `x`.
    fn evaluate(&self, x: &[f64]) -> Self::Eval;
    /// Scores `x`, which differs from the position `base` scored only in vehicle `i`'s genes
    /// (an arena that can reuse the rest of `base` overrides this).
    fn evaluate_change(&self, base: &Self::Eval, x: &[f64], i: usize) -> Self::Eval {
        let _ = (base, i);
        self.evaluate(x)
    }
    /// Where vehicle `i`'s chromosome sits in a position.
    fn genes(&self, i: usize) -> Range<usize>;
    /// What a step must lower.
    fn merit(&self, e: &Self::Eval) -> f64;
    /// Weighted penalties (zero: every limit kept).
    fn penalty(&self, e: &Self::Eval) -> f64;
    /// The arrival the others keep, seconds: with the slowest speed, the shortest a path may
    /// be (`None`: an early arrival is allowed).
    fn common_arrival(&self, e: &Self::Eval) -> Option<f64>;
    /// Vehicle `i`'s timed trajectory.
    fn mine<'e>(&'e self, e: &'e Self::Eval, i: usize) -> Samples<'e>;
    /// The other vehicles' timed trajectories.
    fn others<'e>(&'e self, e: &'e Self::Eval, i: usize) -> Vec<Samples<'e>>;
    /// Rows only this arena has (a replan's turn off the vehicle's present course).
    fn extra_rows(&self, _points: &[Vec3], _limits: &Limits, _rows: &mut Vec<Row>) {}
}

/// The state of one refinement.
pub(super) struct Search<'a, A: Arena> {
    pub arena: &'a A,
    pub settings: &'a RefineSettings,
    pub stop: Option<&'a Arc<AtomicBool>>,
    /// The arrival a path's length must allow at top speed, seconds.
    pub target: f64,
    pub x: Vec<f64>,
    pub eval: A::Eval,
    pub evaluations: u64,
    pub steps: usize,
    pub interrupted: bool,
}

impl<'a, A: Arena> Search<'a, A> {
    /// A search from `x`.
    pub fn new(
        arena: &'a A,
        x: &[f64],
        target: f64,
        settings: &'a RefineSettings,
        stop: Option<&'a Arc<AtomicBool>>,
    ) -> Self {
        Search {
            arena,
            settings,
            stop,
            target,
            x: x.to_vec(),
            eval: arena.evaluate(x),
            evaluations: 1,
            steps: 0,
            interrupted: false,
        }
    }

    /// A search of the same arena and settings from `x` (its own counters, from zero).
    pub fn branch(&self, x: Vec<f64>) -> Self {
        Search {
            eval: self.arena.evaluate(&x),
            x,
            evaluations: 1,
            steps: 0,
            interrupted: false,
            ..*self
        }
    }

    /// A copy of this search at its fleet position, with counts of its own.
    pub fn fork(&self) -> Self {
        Search {
            x: self.x.clone(),
            eval: self.eval.clone(),
            evaluations: 0,
            steps: 0,
            interrupted: false,
            ..*self
        }
    }

    /// The stop flag is raised or the deadline has passed.
    fn should_stop(&self) -> bool {
        self.stop.is_some_and(|f| f.load(Ordering::Relaxed))
            || self.settings.deadline.is_some_and(|d| Instant::now() >= d)
    }

    /// Up to `steps` programs for vehicle `i`, the others held.
    pub fn vehicle(&mut self, i: usize) {
        let model = self.arena.model();
        let s = &model.scenario;
        let v = &s.vehicles[i];
        let margin = self.settings.angle_margin_deg;
        let limits = Limits {
            max_pitch: (v.max_pitch_deg - margin).to_radians(),
            max_turn: (v.max_turn_deg - margin).to_radians(),
            clearance_margin: self.settings.distance_margin_m,
            separation: s.fleet.d_min_m + self.settings.distance_margin_m,
            d_min: s.fleet.d_min_m,
        };
        let range = self.arena.genes(i);
        let n = 3 * model.layout.waypoints;
        let coords = range.start..range.start + n;
        let bounds = model.layout.chromosome(i).start;
        let mut radius = self.settings.radius_m;
        let floors = constraints::spacing_floors(&model.decode(i, &self.x[range.clone()]).points);
        for _ in 0..self.settings.steps {
            if self.should_stop() {
                self.interrupted = true;
                return;
            }
            let points = model.decode(i, &self.x[range.clone()]).points;
            let mut rows = self.rows(i, &points, &limits, radius);
            constraints::spacing_rows(&points, &floors, &mut rows);
            if self.arena.penalty(&self.eval) <= 0.0 {
                // A plan that keeps every limit may sit inside a margin: it holds its ground
                // there instead of paying (in the model) for leaving it.
                for row in rows.iter_mut() {
                    row.value = row.value.min(0.0);
                }
            }
            let gradient = objective_gradient(model, i, &points);
            let hessian = model_hessian(model, i, &points);
            let (lo, hi): (Vec<f64>, Vec<f64>) = coords
                .clone()
                .map(|g| {
                    let b = bounds + g - range.start;
                    (
                        (model.lower[b] - self.x[g]).max(-radius),
                        (model.upper[b] - self.x[g]).min(radius),
                    )
                })
                .unzip();
            let program = Program {
                hessian: &hessian,
                gradient: &gradient,
                rows: &rows,
                lo: &lo,
                hi: &hi,
                rho: s.optimizer.penalty_weight,
            };
            let Some(step) = program.solve() else {
                return;
            };
            let merit = self.arena.merit(&self.eval);
            if step.predicted > -1e-12 * merit.abs().max(1.0) {
                return;
            }
            let longest = step.d.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
            match self.try_step(i, &coords, &step.d) {
                Some((scale, actual)) => {
                    self.steps += 1;
                    let ratio = actual / step.predicted;
                    if scale < 1.0 {
                        radius = scale * longest;
                    } else if ratio > 0.75 && longest > 0.9 * radius {
                        radius = (2.0 * radius).min(8.0 * self.settings.radius_m);
                    } else if ratio < 0.25 {
                        radius = 0.5 * longest;
                    }
                }
                None => radius = 0.125 * longest,
            }
            if radius < self.settings.min_radius_m {
                return;
            }
        }
    }

    /// Moves the genes `coords` by `d`, or by a half or a quarter of it when the whole step
    /// does not lower the merit (a step the linearised limits allowed may cross a curved
    /// limit: halving it quarters that second-order error). Returns the fraction kept and the
    /// change of merit, or `None` when no fraction lowered it.
    fn try_step(&mut self, i: usize, coords: &Range<usize>, d: &[f64]) -> Option<(f64, f64)> {
        let mut scale = 1.0;
        let now = self.arena.merit(&self.eval);
        for _ in 0..3 {
            let mut trial = self.x.clone();
            for (g, d) in coords.clone().zip(d) {
                trial[g] += scale * d;
            }
            let e = self.arena.evaluate_change(&self.eval, &trial, i);
            self.evaluations += 1;
            let actual = self.arena.merit(&e) - now;
            if actual < 0.0 {
                self.x = trial;
                self.eval = e;
                return Some((scale, actual / scale));
            }
            scale *= 0.5;
        }
        None
    }

    /// The limits of vehicle `i` near its path `points`, the others as the arena has them.
    fn rows(&self, i: usize, points: &[Vec3], limits: &Limits, radius: f64) -> Vec<Row> {
        let model = self.arena.model();
        let s = &model.scenario;
        let v = &s.vehicles[i];
        // Limits a step of `radius` per coordinate could reach, with room to spare.
        let reach = 4.0 * radius + s.fleet.d_min_m;
        let mut rows = Vec::new();
        constraints::pitch_rows(points, limits, &mut rows);
        constraints::turn_rows(points, limits, &mut rows);
        constraints::hard_rows(points, &model.hard, limits, reach, &mut rows);
        constraints::soft_rows(points, &model.soft, reach, &mut rows);
        self.arena.extra_rows(points, limits, &mut rows);
        let mine = self.arena.mine(&self.eval, i);
        let step = self.settings.sample_step_s;
        let others = self.arena.others(&self.eval, i);
        // Only the trajectories that come near are copied for the rows' sampling.
        let mut near = coming_near(mine, others, limits.separation + reach).peekable();
        if near.peek().is_some() {
            let mine = owned(mine);
            for (other, windows) in near {
                let other = owned(other);
                constraints::separation_rows(
                    &mine, &other, limits, step, reach, &windows, &mut rows,
                );
            }
        }
        let latest = v.speed_max_mps * self.target;
        rows.extend(constraints::length_row(points, latest, 1.0));
        if let Some(arrival) = self.arena.common_arrival(&self.eval) {
            let earliest = v.speed_min_mps * arrival;
            rows.extend(constraints::length_row(points, earliest, -1.0));
        }
        rows
    }
}

/// The trajectories of `others` whose slab boxes ([`SlabBoxes`]) come within `reach` of
/// `mine`'s at some instant, each with the time windows of the slabs where they do: only those
/// can come within `reach` of it, and only then, so only they add a separation row (which
/// sampling every one over the whole mission would find out far more slowly).
fn coming_near<'e>(
    (times, points): Samples<'_>,
    others: Vec<Samples<'e>>,
    reach: f64,
) -> impl Iterator<Item = (Samples<'e>, Vec<(f64, f64)>)> {
    let arrival = |times: &[f64]| times.last().copied().unwrap_or(0.0);
    let horizon = (others.iter())
        .map(|t| arrival(t.0))
        .fold(arrival(times), f64::max);
    let (mut own, mut other_boxes) = (SlabBoxes::new(), SlabBoxes::new());
    own.reset(horizon);
    own.push(times, points);
    let whole = extent(points);
    others.into_iter().filter_map(move |t| {
        // Whole trajectories apart prove every slab apart, for a box test instead of a slab pass.
        if !boxes_within(&whole, &extent(t.1), reach) {
            return None;
        }
        other_boxes.reset(horizon);
        other_boxes.push(t.0, t.1);
        let slabs = own.near_slabs_other(0, &other_boxes, 0, reach);
        if slabs == 0 {
            return None;
        }
        let mut windows = Vec::new();
        own.windows(slabs, &mut windows);
        Some((t, windows))
    })
}

/// A copy of borrowed samples as a trajectory of its own.
fn owned((times, points): Samples<'_>) -> Trajectory {
    Trajectory {
        times: times.to_vec(),
        points: points.to_vec(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(from: [f64; 3], to: [f64; 3], seconds: f64) -> Trajectory {
        Trajectory {
            times: vec![0.0, seconds],
            points: vec![Vec3::from(from), Vec3::from(to)],
        }
    }

    /// Of three others, the one that passes 30 m from `mine` is kept; the parallel one 400 m
    /// away and the one that crosses `mine`'s track 500 s after `mine` has passed are left out,
    /// and neither adds a separation row when sampled over the whole mission.
    #[test]
    fn only_others_that_come_near_are_sampled() {
        let mine = line([0., 0., 100.], [1000., 0., 100.], 1000.0);
        let near = line([0., 30., 100.], [1000., 30., 100.], 1000.0);
        let parallel = line([0., 400., 100.], [1000., 400., 100.], 1000.0);
        let late = line([100., 1000., 100.], [100., -1000., 100.], 2000.0);
        let limits = Limits {
            max_pitch: 0.3,
            max_turn: 0.6,
            clearance_margin: 1.0,
            separation: 55.0,
            d_min: 50.0,
        };
        let reach = 60.0;
        fn samples(t: &Trajectory) -> Samples<'_> {
            (&t.times, &t.points)
        }
        let others = [&near, &parallel, &late].map(samples).to_vec();
        let kept: Vec<_> = coming_near(samples(&mine), others, limits.separation + reach)
            .map(|(t, _)| owned(t))
            .collect();
        assert_eq!(kept, std::slice::from_ref(&near));
        let whole = constraints::WHOLE_MISSION;
        for other in [&parallel, &late] {
            let mut rows = Vec::new();
            constraints::separation_rows(&mine, other, &limits, 2.0, reach, &whole, &mut rows);
            assert!(rows.is_empty());
        }
        let mut rows = Vec::new();
        constraints::separation_rows(&mine, &near, &limits, 2.0, reach, &whole, &mut rows);
        assert!(!rows.is_empty());
    }
}
