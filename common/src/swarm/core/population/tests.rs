use super::*;
use approx::assert_abs_diff_eq;

#[test]
fn adaptive_schedule_follows_eq_7_and_8() {
    let at = |a, b| {
        Schedule::Adaptive.at(Progress {
            iteration: a,
            max_iterations: b,
        })
    };
    let c = at(0, 200);
    assert_eq!((c.w, c.c1, c.c2, c.c3), (2.0, 2.0, 1.0, 2.0));
    let c = at(50, 200);
    assert_abs_diff_eq!(c.w, 1.5);
    assert_abs_diff_eq!(c.c1, 1.75);
    assert_abs_diff_eq!(c.c2, 1.25);
    assert_abs_diff_eq!(c.c3, 1.75);
    let c = at(200, 200);
    assert_eq!((c.w, c.c1, c.c2, c.c3), (0.0, 1.0, 2.0, 1.0));
    // A budget over Table 5's 200 sweeps again every 200 iterations.
    assert_eq!(at(250, 1000), at(50, 200));
    assert_eq!(at(200, 1000), at(0, 200));
    assert_eq!(at(999, 1000), at(199, 200));
    // Up to 200, one sweep over the budget: half way through 100 is half way.
    assert_eq!(at(50, 100), at(100, 200));
}

#[test]
fn update_with_no_pull_is_pure_inertia_scaled_into_its_limits() {
    let limits = Limits {
        lower: vec![0.0, 0.0],
        upper: vec![10.0, 10.0],
        vmax: vec![3.0, 3.0],
        inv_vmax: vec![1.0 / 3.0, 1.0 / 3.0],
        groups: std::iter::once(0..2).collect(),
    };
    let mut p = Particle {
        x: vec![5.0, 9.0],
        v: vec![1.0, 5.0],
        cost: 0.0,
        parts: vec![0.0],
        best_x: vec![5.0, 9.0],
        best_parts: vec![0.0],
        best_cost: 0.0,
    };
    // Personal and global best equal x: only inertia acts. ω = 2 → v = (2, 10); the second
    // dimension is 10/3 over its cap, so both are scaled by 3/10 → (0.6, 3), keeping the
    // direction. x = (5.6, 12) → the wall at 10 stops the second dimension.
    let c = Coefficients {
        w: 2.0,
        c1: 1.5,
        c2: 1.5,
        c3: 0.0,
    };
    let mut rng = StdRng::seed_from_u64(0);
    update(&mut p, &[5.0, 9.0], None, c, &limits, &mut rng);
    assert_abs_diff_eq!(p.x[0], 5.6, epsilon = 1e-12);
    assert_abs_diff_eq!(p.x[1], 10.0);
    assert_abs_diff_eq!(p.v[0], 0.6, epsilon = 1e-12);
    assert_abs_diff_eq!(p.v[1], 0.0);
    // Per-dimension groups clamp each dimension on its own: (2, 10) → (2, 3).
    let per_dim = Limits {
        groups: vec![0..1, 1..2],
        ..limits
    };
    p.x = vec![5.0, 5.0];
    p.best_x = vec![5.0, 5.0];
    p.v = vec![1.0, 5.0];
    update(&mut p, &[5.0, 5.0], None, c, &per_dim, &mut rng);
    assert_eq!(p.x, vec![7.0, 8.0]);
}

/// A problem of two one-dimensional blocks on [−10, 10]², its per-block costs given by `f`.
struct TwoBlocks<F: Fn(&[f64]) -> [f64; 2] + Sync>(F);
impl<F: Fn(&[f64]) -> [f64; 2] + Sync> Problem for TwoBlocks<F> {
    fn lower(&self) -> &[f64] {
        &[-10.0, -10.0]
    }
    fn upper(&self) -> &[f64] {
        &[10.0, 10.0]
    }
    fn cost(&self, x: &[f64]) -> f64 {
        (self.0)(x).iter().sum()
    }
    fn blocks(&self) -> usize {
        2
    }
    fn block_range(&self, b: usize) -> std::ops::Range<usize> {
        b..b + 1
    }
    fn cost_parts(&self, x: &[f64], parts: &mut [f64]) -> f64 {
        let p = (self.0)(x);
        parts.copy_from_slice(&p);
        p[0] + p[1]
    }
}

/// Independent blocks: cost = (x0 − 1)² + (x1 − 2)².
fn independent(x: &[f64]) -> [f64; 2] {
    [(x[0] - 1.0).powi(2), (x[1] - 2.0).powi(2)]
}

/// Blocks coupled like two vehicles: each pays 5 when they are closer than 1.
fn coupled(x: &[f64]) -> [f64; 2] {
    let clash = if (x[0] - x[1]).abs() < 1.0 { 5.0 } else { 0.0 };
    [x[0] * x[0] + clash, x[1] * x[1] + clash]
}

#[test]
fn an_assembled_best_that_clashes_is_not_followed() {
    // a = (0, 3): parts (0, 9), cost 9. b = (3, 0.5): parts (9, 0.25), cost 9.25.
    // Block by block the best is (0, 0.5), but those two clash: true cost 0 + 0.25 + 10.
    let a = Particle::new(&TwoBlocks(coupled), vec![0.0, 3.0]);
    let b = Particle::new(&TwoBlocks(coupled), vec![3.0, 0.5]);
    let best = trusted_best(&TwoBlocks(coupled), [&a, &b].into_iter(), &a.x, a.cost);
    assert_eq!(
        best,
        Some(TrustedBest {
            x: vec![0.0, 3.0],
            cost: 9.0,
            evaluations: 1
        })
    );
    let pop = Population::from_particles(&TwoBlocks(coupled), vec![a, b], StdRng::seed_from_u64(1));
    assert_eq!((pop.gbest.clone(), pop.elite_cost), (vec![0.0, 3.0], 9.0));
}

/// Blocks coupled the other way round: each pays the distance between them, so a block's
/// memory can be cheaper than the same block next to another partner.
fn tethered(x: &[f64]) -> [f64; 2] {
    let d = (x[0] - x[1]).abs();
    [x[0] * x[0] + d, x[1] * x[1] + d]
}

#[test]
fn an_assembled_best_equal_to_the_elite_costs_what_the_elite_truly_costs() {
    // e = (0, 3): parts (0 + 3, 9 + 3), cost 15. o = (3, 3): parts (9, 9), cost 18.
    // Block 0 comes from e (3 < 9), block 1 from o (9 < 12): the assembled best is (0, 3),
    // the elite itself, whose cost is 15 and not the remembered 3 + 9 = 12.
    let e = Particle::new(&TwoBlocks(tethered), vec![0.0, 3.0]);
    let o = Particle::new(&TwoBlocks(tethered), vec![3.0, 3.0]);
    let best = trusted_best(&TwoBlocks(tethered), [&e, &o].into_iter(), &e.x, e.cost);
    assert_eq!(
        best,
        Some(TrustedBest {
            x: vec![0.0, 3.0],
            cost: 15.0,
            evaluations: 0
        })
    );
    let pop =
        Population::from_particles(&TwoBlocks(tethered), vec![e, o], StdRng::seed_from_u64(1));
    assert_eq!(
        (pop.elite_x.clone(), pop.elite_cost),
        (vec![0.0, 3.0], 15.0)
    );
}

#[test]
fn memories_are_kept_block_by_block() {
    let mut p = Particle::new(&TwoBlocks(independent), vec![3.0, 2.0]); // parts (4, 0)
    p.x = vec![1.0, 5.0]; // parts (0, 9): block 0 improves, block 1 does not
    p.evaluate(&TwoBlocks(independent));
    assert_eq!(p.cost, 9.0);
    assert_eq!(p.best_x, vec![1.0, 2.0]);
    assert_eq!(p.best_parts, vec![0.0, 0.0]);
    assert_eq!(p.best_cost, 0.0);
    // Assembling takes block 0 from one particle and block 1 from another; the elite is the
    // assembled position once it is evaluated.
    let a = Particle::new(&TwoBlocks(independent), vec![1.0, 7.0]);
    let b = Particle::new(&TwoBlocks(independent), vec![6.0, 2.0]);
    let pop = Population::from_particles(
        &TwoBlocks(independent),
        vec![a, b],
        StdRng::seed_from_u64(1),
    );
    assert_eq!(pop.gbest, vec![1.0, 2.0]);
    assert_eq!(pop.elite_x, vec![1.0, 2.0]);
    assert_eq!(pop.elite_cost, 0.0);
}

/// [`update`] as eq. (5)–(6) first read here: the velocity limit as one `f64::max` chain and the
/// clamp as branches. The update's faster form must give the same bits.
fn update_as_written(
    p: &mut Particle,
    gbest: &[f64],
    exchange: Option<&[f64]>,
    c: Coefficients,
    limits: &Limits,
    rng: &mut StdRng,
) {
    for g in &limits.groups {
        let (r1, r2): (f64, f64) = (rng.random(), rng.random());
        let (a1, a2) = (c.c1 * r1, c.c2 * r2);
        for d in g.clone() {
            p.v[d] = c.w * p.v[d] + a1 * (p.best_x[d] - p.x[d]) + a2 * (gbest[d] - p.x[d]);
        }
        if let Some(f) = exchange {
            let a3 = c.c3 * rng.random::<f64>();
            for d in g.clone() {
                p.v[d] += a3 * (f[d] - p.x[d]);
            }
        }
        let over = g
            .clone()
            .fold(1.0f64, |m, d| m.max(p.v[d].abs() * limits.inv_vmax[d]));
        for d in g.clone() {
            let moved = p.v[d] * (1.0 / over);
            let to = p.x[d] + moved;
            if to < limits.lower[d] {
                (p.x[d], p.v[d]) = (limits.lower[d], 0.0);
            } else if to > limits.upper[d] {
                (p.x[d], p.v[d]) = (limits.upper[d], 0.0);
            } else {
                (p.x[d], p.v[d]) = (to, moved);
            }
        }
    }
}

/// A coordinate for the update's property test: mostly ordinary, sometimes a wall, a zero of
/// either sign or a NaN.
fn coordinate() -> impl proptest::strategy::Strategy<Value = f64> {
    use proptest::prelude::*;
    prop_oneof![
        8 => -20.0..20.0f64,
        1 => Just(-10.0),
        1 => Just(10.0),
        1 => Just(0.0),
        1 => Just(-0.0),
        1 => Just(f64::NAN),
    ]
}

proptest::proptest! {
    /// The vectorised limit and the branch-free clamp change no bit of a move, with or without
    /// the exchange, whatever the group sizes (remainders of the four-wide loop included), at
    /// walls of either sign and at walls of signed zeros.
    #[test]
    fn the_update_moves_as_written_to_the_last_bit(
        dims in proptest::collection::vec((coordinate(), coordinate(), coordinate(), coordinate(), coordinate()), 1..40),
        cut in 0usize..40,
        (lo, hi) in proptest::prop_oneof![
            proptest::strategy::Just((-10.0, 10.0)),
            proptest::strategy::Just((0.0, 10.0)),
            proptest::strategy::Just((-10.0, -0.0)),
            proptest::strategy::Just((-0.0, 0.0)),
        ],
        exchange in proptest::prelude::any::<bool>(),
        seed in proptest::prelude::any::<u64>(),
    ) {
        let n = dims.len();
        let cut = cut.min(n);
        let groups: Vec<_> = [0..cut, cut..n].into_iter().filter(|g| !g.is_empty()).collect();
        let vmax = vec![3.0; n];
        let limits = Limits {
            lower: vec![lo; n],
            upper: vec![hi; n],
            inv_vmax: inverses(&vmax),
            vmax,
            groups,
        };
        let column = |k: usize| dims.iter().map(|d| [d.0, d.1, d.2, d.3, d.4][k]).collect::<Vec<f64>>();
        let mut ours = Particle {
            x: column(0),
            v: column(1),
            cost: 0.0,
            parts: vec![0.0],
            best_x: column(2),
            best_parts: vec![0.0],
            best_cost: 0.0,
        };
        let (gbest, followers) = (column(3), column(4));
        let exchange = exchange.then_some(followers.as_slice());
        let c = Coefficients { w: 0.9, c1: 1.5, c2: 1.7, c3: 1.1 };
        let mut theirs = ours.clone();
        update(&mut ours, &gbest, exchange, c, &limits, &mut StdRng::seed_from_u64(seed));
        update_as_written(&mut theirs, &gbest, exchange, c, &limits, &mut StdRng::seed_from_u64(seed));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        proptest::prop_assert_eq!(bits(&ours.x), bits(&theirs.x));
        proptest::prop_assert_eq!(bits(&ours.v), bits(&theirs.v));
    }
}
