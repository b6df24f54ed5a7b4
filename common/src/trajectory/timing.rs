//! When a vehicle can arrive, the fleet's common arrival, and the sample times that bring a
//! vehicle in at a given time (Zhi & Zuo 2024, eq. (2) and §2.2.2): [`super::retime`] on leg
//! lengths and speeds alone, so the fitness times every vehicle on buffers it reuses.

use crate::scenario::Vehicle;

/// Earliest and latest arrival a path allows: `t_min = L / v_max`, `t_max = L / v_min`
/// (Zhi & Zuo 2024, eq. (2)), seconds.
pub fn arrival_window(length: f64, vehicle: &Vehicle) -> (f64, f64) {
    (
        length / vehicle.speed_max_mps,
        length / vehicle.speed_min_mps,
    )
}

/// The arrival time all vehicles aim for: the mission time when every vehicle can make it, else
/// the earliest time the slowest-to-arrive vehicle can make (Zhi & Zuo 2024, §2.2.2: the task "cannot be
/// completed on time"). Never earlier than the mission time.
pub fn common_arrival(mission_time: f64, earliest: impl IntoIterator<Item = f64>) -> f64 {
    earliest.into_iter().fold(mission_time, f64::max)
}

/// The sample times of [`retime`](super::retime) for legs of `lengths` at the requested
/// `speeds` (one per leg, overwritten with the legs' requested paces), appended to `times` (one
/// more than legs; what it held before stays): what the fitness calls on the one buffer it
/// times the whole fleet into, so timing a path allocates nothing.
pub fn leg_times(
    lengths: &[f64],
    speeds: &mut [f64],
    vehicle: &Vehicle,
    target: f64,
    times: &mut Vec<f64>,
) {
    let (p_lo, p_hi) = (1.0 / vehicle.speed_max_mps, 1.0 / vehicle.speed_min_mps);
    let kept = times.len();
    let total: f64 = lengths.iter().sum();
    // Each leg's requested pace (s/m), computed once: the search below revisits every leg
    // several times.
    for v in speeds.iter_mut() {
        *v = 1.0 / v.clamp(vehicle.speed_min_mps, vehicle.speed_max_mps);
    }
    let paces = &*speeds;
    if total * p_lo >= target {
        // Too long to make it: flat out.
        time_legs(lengths, p_lo, kept, times);
        return;
    }
    if total * p_hi <= target {
        // Too short to be late: as slow as it goes.
        time_legs(lengths, p_hi, kept, times);
        return;
    }
    times.reserve(lengths.len() + 1);
    let legs = PacedLegs {
        lengths,
        paces,
        p_lo,
        p_hi,
        kept,
    };
    legs.time_to(target, times);
}

/// Legs of `lengths` at their requested `paces` (s/m), each pace clamped to `[p_lo, p_hi]`
/// once scaled, timed into a buffer after its first `kept` entries.
struct PacedLegs<'a> {
    lengths: &'a [f64],
    paces: &'a [f64],
    p_lo: f64,
    p_hi: f64,
    kept: usize,
}

impl PacedLegs<'_> {
    /// Times the legs so the last arrives at `target` (which the clamped paces can reach): a
    /// Newton step on the current linear piece of `T(α)`, safeguarded by a bisection bracket.
    /// The search stops on a step it has just timed, so `times` holds its answer.
    fn time_to(&self, target: f64, times: &mut Vec<f64>) {
        let (max_p, min_p) =
            (self.paces.iter()).fold((f64::MIN, f64::MAX), |(hi, lo), p| (hi.max(*p), lo.min(*p)));
        let (mut lo, mut hi) = (self.p_lo / max_p, self.p_hi / min_p);
        // Start from the unclamped solution.
        let free: f64 = (self.lengths.iter().zip(self.paces))
            .map(|(l, p)| l * p)
            .sum();
        let mut a = (target / free).clamp(lo, hi);
        for _ in 0..100 {
            let (t, slope) = self.time_at(a, times);
            let err = t - target;
            if err.abs() <= 1e-12 * target {
                return;
            }
            if err < 0.0 {
                lo = a;
            } else {
                hi = a;
            }
            let newton = if slope > 0.0 {
                a - err / slope
            } else {
                f64::NAN
            };
            a = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if hi - lo <= 1e-15 * hi {
                break;
            }
        }
        self.time_at(a, times);
    }

    /// The samples' times at pace factor `α` into `times`, and `T(α)` with its slope on the
    /// current piece (the free legs' `Σ l p`; adding 0.0 leaves it as it was). Selects, not
    /// branches: which legs are clamped changes from leg to leg, so branches mispredict.
    #[inline]
    fn time_at(&self, a: f64, times: &mut Vec<f64>) -> (f64, f64) {
        let (mut t, mut slope) = (0.0, 0.0);
        times.truncate(self.kept);
        times.push(0.0);
        for (l, &p) in self.lengths.iter().zip(self.paces) {
            let q = a * p;
            let (slow, fast) = (q <= self.p_lo, q >= self.p_hi);
            let pace = if slow {
                self.p_lo
            } else if fast {
                self.p_hi
            } else {
                q
            };
            t += l * pace;
            slope += if slow || fast { 0.0 } else { l * p };
            times.push(t);
        }
        (t, slope)
    }
}

/// The sample times of legs of `lengths` all flown at `pace` (s/m), into `times` after its
/// first `kept` (from 0, one more than legs).
fn time_legs(lengths: &[f64], pace: f64, kept: usize, times: &mut Vec<f64>) {
    let mut t = 0.0;
    times.truncate(kept);
    times.push(0.0);
    times.extend(lengths.iter().map(|l| {
        t += l * pace;
        t
    }));
}
