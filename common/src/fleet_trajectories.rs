//! A fleet's timed trajectories in two contiguous buffers (structure of arrays): every
//! vehicle's sample times one after the other in one, its positions in the same places of the
//! other. The fitness writes a fleet hundreds of thousands of times; one buffer per kind keeps
//! a whole fleet's samples in a few streams the cache prefetches, grows once for all vehicles,
//! and is copied whole with two allocations instead of two per vehicle.

use crate::geometry::Vec3;
use crate::trajectory::Trajectory;

/// Every vehicle's timed trajectory, vehicle `i`'s samples at `starts[i]..starts[i + 1]` of
/// both buffers.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetTrajectories {
    /// Sample times, seconds, vehicle after vehicle.
    times: Vec<f64>,
    /// Sample positions, metres, in the same places.
    points: Vec<Vec3>,
    /// Where each vehicle's samples start, then where the last one's end (one more than
    /// vehicles, beginning with 0).
    starts: Vec<usize>,
}

impl Default for FleetTrajectories {
    fn default() -> FleetTrajectories {
        FleetTrajectories {
            times: Vec::new(),
            points: Vec::new(),
            starts: vec![0],
        }
    }
}

impl FleetTrajectories {
    /// Vehicles.
    pub fn len(&self) -> usize {
        self.starts.len() - 1
    }

    /// True with no vehicle.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Vehicle `i`'s sample times (empty past the last vehicle).
    pub fn times(&self, i: usize) -> &[f64] {
        self.times.get(self.span(i)).unwrap_or(&[])
    }

    /// Vehicle `i`'s sample positions (empty past the last vehicle).
    pub fn points(&self, i: usize) -> &[Vec3] {
        self.points.get(self.span(i)).unwrap_or(&[])
    }

    /// Vehicle `i`'s arrival, its last sample's time (0 without samples).
    pub fn arrival(&self, i: usize) -> f64 {
        self.times(i).last().copied().unwrap_or(0.0)
    }

    /// Vehicle `i`'s trajectory as one of its own (empty past the last vehicle).
    pub fn trajectory(&self, i: usize) -> Trajectory {
        Trajectory {
            times: self.times(i).to_vec(),
            points: self.points(i).to_vec(),
        }
    }

    /// Every vehicle's trajectory as one of its own, in vehicle order: what plans, messages
    /// and reports keep.
    pub fn to_vec(&self) -> Vec<Trajectory> {
        (0..self.len()).map(|i| self.trajectory(i)).collect()
    }

    /// Every vehicle's times and positions, in vehicle order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (&[f64], &[Vec3])> + '_ {
        (0..self.len()).map(|i| (self.times(i), self.points(i)))
    }

    /// These trajectories with vehicle `i`'s replaced by `t` (a copy of the rest, in two
    /// allocations); the same if there is no vehicle `i`.
    pub fn with_replaced(&self, i: usize, t: &Trajectory) -> FleetTrajectories {
        if i >= self.len() {
            return self.clone();
        }
        let samples = t.times.len().min(t.points.len());
        let (from, to) = (self.starts[i], self.starts[i + 1]);
        let size = self.times.len() - (to - from) + samples;
        let mut out = FleetTrajectories {
            times: Vec::with_capacity(size),
            points: Vec::with_capacity(size),
            starts: Vec::with_capacity(self.starts.len()),
        };
        out.times.extend_from_slice(&self.times[..from]);
        out.times.extend_from_slice(&t.times[..samples]);
        out.times.extend_from_slice(&self.times[to..]);
        out.points.extend_from_slice(&self.points[..from]);
        out.points.extend_from_slice(&t.points[..samples]);
        out.points.extend_from_slice(&self.points[to..]);
        out.starts.extend_from_slice(&self.starts[..=i]);
        out.starts.extend(
            self.starts[i + 1..]
                .iter()
                .map(|s| s - (to - from) + samples),
        );
        out
    }

    /// Forgets every vehicle, keeping the buffers.
    pub fn clear(&mut self) {
        self.times.clear();
        self.points.clear();
        self.starts.clear();
        self.starts.push(0);
    }

    /// Adds the next vehicle's path, untimed: `decode` appends its positions to the buffer it
    /// is given. Its times come from [`FleetTrajectories::time_each`].
    pub fn push_path(&mut self, decode: impl FnOnce(&mut Vec<Vec3>)) {
        decode(&mut self.points);
        self.starts.push(self.points.len());
    }

    /// Times every vehicle, in order: `time` appends vehicle `i`'s sample times to the buffer
    /// it is given (one per position; a wrong count is cut or padded with the last time so the
    /// buffers stay aligned), then `timed` gets its times and positions while they are fresh
    /// in the cache.
    pub fn time_each(
        &mut self,
        mut time: impl FnMut(usize, &mut Vec<f64>),
        mut timed: impl FnMut(&[f64], &[Vec3]),
    ) {
        self.times.clear();
        for i in 0..self.len() {
            let (from, to) = (self.starts[i], self.starts[i + 1]);
            time(i, &mut self.times);
            let last = (self.times.get(from..).and_then(|t| t.last())).map_or(0.0, |t| *t);
            self.times.resize(to, last);
            timed(&self.times[from..to], &self.points[from..to]);
        }
    }

    fn span(&self, i: usize) -> std::ops::Range<usize> {
        match (self.starts.get(i), self.starts.get(i + 1)) {
            (Some(&from), Some(&to)) => from..to,
            _ => 0..0,
        }
    }
}

impl From<&[Trajectory]> for FleetTrajectories {
    fn from(trajectories: &[Trajectory]) -> FleetTrajectories {
        trajectories.iter().collect()
    }
}

impl<'a> FromIterator<&'a Trajectory> for FleetTrajectories {
    /// The trajectories in the order given (each cut to the shorter of its times and
    /// positions).
    fn from_iter<I: IntoIterator<Item = &'a Trajectory>>(trajectories: I) -> FleetTrajectories {
        let mut out = FleetTrajectories::default();
        for t in trajectories {
            let samples = t.times.len().min(t.points.len());
            out.times.extend_from_slice(&t.times[..samples]);
            out.points.extend_from_slice(&t.points[..samples]);
            out.starts.push(out.points.len());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(t0: f64, n: usize) -> Trajectory {
        Trajectory {
            times: (0..n).map(|k| t0 + k as f64).collect(),
            points: (0..n).map(|k| Vec3::new(t0, k as f64, 0.0)).collect(),
        }
    }

    #[test]
    fn holds_each_vehicle_where_it_was_put() {
        let fleet = vec![track(0.0, 3), track(10.0, 1), track(20.0, 4)];
        let flat = FleetTrajectories::from(&fleet[..]);
        assert_eq!(flat.len(), 3);
        assert_eq!(flat.to_vec(), fleet);
        assert_eq!(flat.times(1), &[10.0]);
        assert_eq!(flat.points(2)[3], Vec3::new(20.0, 3.0, 0.0));
        assert_eq!(flat.arrival(2), 23.0);
        assert!(flat.times(3).is_empty() && flat.points(7).is_empty());
        assert_eq!(
            flat.iter().map(|(t, _)| t.len()).collect::<Vec<_>>(),
            [3, 1, 4]
        );
    }

    #[test]
    fn replacing_one_vehicle_moves_the_ones_after_it() {
        let fleet = vec![track(0.0, 3), track(10.0, 1), track(20.0, 4)];
        let flat = FleetTrajectories::from(&fleet[..]);
        for (i, n) in [(0, 5), (1, 2), (2, 1), (1, 0)] {
            let mut expected = fleet.clone();
            expected[i] = track(100.0, n);
            assert_eq!(flat.with_replaced(i, &expected[i]).to_vec(), expected);
        }
        assert_eq!(flat.with_replaced(3, &track(1.0, 1)), flat);
    }

    #[test]
    fn timing_fills_each_vehicle_with_as_many_times_as_positions() {
        let mut flat = FleetTrajectories::default();
        flat.push_path(|p| p.extend([Vec3::zeros(), Vec3::x()]));
        flat.push_path(|p| p.extend([Vec3::y(), Vec3::y(), Vec3::z()]));
        flat.push_path(|p| p.push(Vec3::z()));
        let mut seen = Vec::new();
        // Vehicle 1 gets one time too few, vehicle 2 one too many.
        let counts = [2, 2, 2];
        flat.time_each(
            |i, times| times.extend((0..counts[i]).map(|k| (10 * i + k) as f64)),
            |t, p| seen.push((t.to_vec(), p.len())),
        );
        assert_eq!(
            seen,
            [
                (vec![0.0, 1.0], 2),
                (vec![10.0, 11.0, 11.0], 3),
                (vec![20.0], 1)
            ]
        );
        assert_eq!(flat.times(1), &[10.0, 11.0, 11.0]);
        flat.clear();
        assert!(flat.is_empty());
    }
}
