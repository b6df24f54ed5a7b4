//! Variable-weight Model Predictive Control, V-MPC (CPP-DSMV, §2.3.2, rebuilt), solved as a dense
//! condensed QP with Clarabel.
//!
//! CPP-DSMV, §2.3.2, error model in the path (Frenet) frame about the reference point, with the
//! actuator lags of the plant as extra states, z = [e_y, e_ψ, ω_a, v_a], u = [ω_c, v_c]:
//!   ė_y = a·e_ψ + w_y                       (a = η·v_r, w_y = predicted lateral drift)
//!   ė_ψ = ω_a − κ·η·v_a − κ²·a·e_y          (linearised ω − κ·ṡ, ṡ = η·v·cos e_ψ/(1 − κ e_y))
//!   ω̇_a = (ω_c − ω_a)/τ_ω,   v̇_a = (v_c − v_a)/τ_v,
//! discretised exactly (zero-order hold) over T: [A_d B_d] from expm([[A_c, B_c],[0, 0]]·T),
//! cached by (κ, η) quantised to 1e-5 1/m and 1/400 (the affine and feed-forward terms use the
//! exact η).
//!
//! Cost (inputs blocked after N_c: u_k = u_(N_c−1) for k ≥ N_c):
//!   J = Σ_(k=1..N_p) f_k·[q_y(κ_k)·e_y,k² + q_ψ(κ_k)·(e_ψ,k − β_k)²]
//!     + Σ_(k=0..N_p−1) [r_ω·(ω_k − κ_k η_k v_r)² + r_v·(v_k − v_r)²]
//!     + Σ_(j=0..N_c−1) [r_Δω(κ_j)·(ω_j − ω_(j−1))² + r_Δv·(v_j − v_(j−1))²],
//! with f_(N_p) = terminal factor (else 1), β_k = −w_y,k/a_k the crab angle that cancels the drift,
//! and (ω_(−1), v_(−1)) the previous command. Hard constraints for j < N_c:
//!   v_min ≤ v_j ≤ v_max,  |ω_j| ≤ (1 + m)·v_j/R_min,  |ω_j − ω_(j−1)| ≤ α_max·T,
//!   |v_j − v_(j−1)| ≤ a_max·T.

use super::params::TrackingParams;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

pub use super::discrete::StageRef;
use super::discrete::{discretise, stage_key, Aug, CACHE_LEN, NZ};

/// A command pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Yaw rate, rad/s.
    pub yaw_rate: f64,
    /// Speed, m/s.
    pub speed: f64,
}

/// The V-MPC weights at one stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageWeights {
    /// Lateral-error weight, 1/m².
    pub q_lat: f64,
    /// Heading-error weight, 1/rad².
    pub q_head: f64,
    /// Yaw-rate change weight, s²/rad².
    pub rd_yaw_rate: f64,
}

/// CPP-DSMV, §2.3.2, the variable-weight law: with the normalised curvature ρ = min(|κ|·R_min, 1),
///   q_y(κ) = q_y,str + ρ·(q_y,arc − q_y,str),  q_ψ(κ) = q_ψ,str + ρ·(q_ψ,arc − q_ψ,str),
///   r_Δω(κ) = r_Δω,str + ρ·(r_Δω,arc − r_Δω,str).
/// On straights the lateral error dominates and yaw-rate changes are expensive (smooth, low
/// sediment shear); in arcs the heading weight rises and yaw-rate changes get cheaper so the
/// controller can follow the curvature step at an arc entry.
pub fn stage_weights(curvature: f64, p: &TrackingParams) -> StageWeights {
    let rho = (curvature.abs() * p.min_turn_radius_m).min(1.0);
    let lerp = |a: f64, b: f64| a + rho * (b - a);
    StageWeights {
        q_lat: lerp(p.q_lat_straight, p.q_lat_arc),
        q_head: lerp(p.q_head_straight, p.q_head_arc),
        rd_yaw_rate: lerp(p.rd_yaw_rate_straight, p.rd_yaw_rate_arc),
    }
}

/// The current tracking problem.
#[derive(Debug, Clone, Copy)]
pub struct MpcProblem<'a> {
    /// Lateral error e_y, m (left positive).
    pub e_lat: f64,
    /// Heading error e_ψ = ψ − ψ_ref, rad.
    pub e_head: f64,
    /// Actuated yaw rate ω_a, rad/s.
    pub yaw_rate_act: f64,
    /// Actuated track speed v_a, m/s.
    pub speed_act: f64,
    /// The command of the previous period.
    pub prev: Command,
    /// Stages k = 0..=N_p.
    pub stages: &'a [StageRef],
}

/// The result of one control step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MpcOutcome {
    /// The command to apply now.
    pub cmd: Command,
    /// Whether the QP solved (false ⇒ `cmd` is the safe fall-back).
    pub solved: bool,
}

/// The V-MPC controller with its QP workspace and a reusable Clarabel solver.
pub struct Mpc {
    params: TrackingParams,
    n_p: usize,
    n_c: usize,
    nv: usize,
    a_mat: CscMatrix<f64>,
    p_colptr: Vec<usize>,
    p_rowval: Vec<usize>,
    n_con: usize,
    solver: Option<DefaultSolver<f64>>,
    h: Vec<f64>,
    f: Vec<f64>,
    b: Vec<f64>,
    p_vals: Vec<f64>,
    m_cur: Vec<f64>,
    m_next: Vec<f64>,
    /// The first input of the last QP optimum, before the final projection (for checks).
    pub last_raw: Option<Command>,
    /// Discretised stage models by quantised (κ, η), oldest first.
    cache: Vec<((i64, i64), Aug)>,
    /// Whether `solver` was built with the robust settings.
    solver_robust: bool,
}

impl std::fmt::Debug for Mpc {
    fn fmt(&self, fm: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        fm.debug_struct("Mpc")
            .field("n_p", &self.n_p)
            .field("n_c", &self.n_c)
            .field("has_solver", &self.solver.is_some())
            .finish()
    }
}

/// Constraint rows per input block.
const ROWS_PER_BLOCK: usize = 8;

impl Mpc {
    /// Sets up the constant QP structure for validated `params`.
    pub fn new(params: &TrackingParams) -> Self {
        let n_c = params.control_horizon;
        let nv = 2 * n_c;
        let c = params.max_curvature();
        // Constraint matrix A (A·U + s = b, s ≥ 0), built column by column; rows per block j:
        // 0: v_j ≤ v_max   1: −v_j ≤ −v_min   2: ω_j − c v_j ≤ 0   3: −ω_j − c v_j ≤ 0
        // 4: ω_j − ω_(j−1) ≤ Δω   5: −ω_j + ω_(j−1) ≤ Δω   6, 7: the same for v.
        let n_con = ROWS_PER_BLOCK * n_c;
        let mut colptr = vec![0usize];
        let mut rowval = Vec::new();
        let mut nzval = Vec::new();
        for col in 0..nv {
            let j = col / 2;
            let is_v = col % 2 == 1;
            let r0 = ROWS_PER_BLOCK * j;
            let mut entries: Vec<(usize, f64)> = if is_v {
                vec![
                    (r0, 1.0),
                    (r0 + 1, -1.0),
                    (r0 + 2, -c),
                    (r0 + 3, -c),
                    (r0 + 6, 1.0),
                    (r0 + 7, -1.0),
                ]
            } else {
                vec![(r0 + 2, 1.0), (r0 + 3, -1.0), (r0 + 4, 1.0), (r0 + 5, -1.0)]
            };
            if j + 1 < n_c {
                let r1 = ROWS_PER_BLOCK * (j + 1);
                if is_v {
                    entries.extend([(r1 + 6, -1.0), (r1 + 7, 1.0)]);
                } else {
                    entries.extend([(r1 + 4, -1.0), (r1 + 5, 1.0)]);
                }
            }
            for (r, v) in entries {
                rowval.push(r);
                nzval.push(v);
            }
            colptr.push(rowval.len());
        }
        let a_mat = CscMatrix::new(n_con, nv, colptr, rowval, nzval);
        // P: dense upper triangle, column-major.
        let mut p_colptr = vec![0usize];
        let mut p_rowval = Vec::new();
        for col in 0..nv {
            p_rowval.extend(0..=col);
            p_colptr.push(p_rowval.len());
        }
        let nnz = p_rowval.len();
        Self {
            params: params.clone(),
            n_p: params.horizon_steps,
            n_c,
            nv,
            a_mat,
            p_colptr,
            p_rowval,
            n_con,
            solver: None,
            h: vec![0.0; nv * nv],
            f: vec![0.0; nv],
            b: vec![0.0; n_con],
            p_vals: vec![0.0; nnz],
            m_cur: vec![0.0; NZ * nv],
            m_next: vec![0.0; NZ * nv],
            last_raw: None,
            cache: Vec::with_capacity(CACHE_LEN),
            solver_robust: false,
        }
    }

    /// Interior-point iterations and solver-reported time (s) of the last QP solve.
    pub fn last_solve_stats(&self) -> Option<(u32, f64)> {
        self.solver
            .as_ref()
            .map(|s| (s.solution.iterations, s.solution.solve_time))
    }

    /// One control step. `problem.stages` must hold N_p + 1 stages (fewer are padded with the
    /// last one). Never fails: when the QP does not solve, the previous command projected on the
    /// limits is returned with `solved = false` (the safe fall-back: hold course and speed).
    pub fn step(&mut self, problem: &MpcProblem<'_>) -> MpcOutcome {
        let prev = project_command(problem.prev, problem.prev, &self.params, false);
        if problem.stages.is_empty() {
            return MpcOutcome {
                cmd: prev,
                solved: false,
            };
        }
        self.build_cost(problem);
        self.build_bounds(prev);
        let mut idx = 0;
        for col in 0..self.nv {
            for row in 0..=col {
                self.p_vals[idx] = self.h[row * self.nv + col];
                idx += 1;
            }
        }
        let solved = self.solve();
        match solved {
            Some(x) if x.iter().all(|v| v.is_finite()) => {
                let raw = Command {
                    yaw_rate: x[0],
                    speed: x[1],
                };
                self.last_raw = Some(raw);
                MpcOutcome {
                    cmd: project_command(raw, prev, &self.params, true),
                    solved: true,
                }
            }
            _ => {
                self.last_raw = None;
                MpcOutcome {
                    cmd: prev,
                    solved: false,
                }
            }
        }
    }

    fn build_cost(&mut self, problem: &MpcProblem<'_>) {
        let Self {
            params: p,
            nv,
            n_p,
            n_c,
            h,
            f,
            m_cur,
            m_next,
            cache,
            ..
        } = self;
        let (nv, n_p, n_c) = (*nv, *n_p, *n_c);
        h.iter_mut().for_each(|v| *v = 0.0);
        f.iter_mut().for_each(|v| *v = 0.0);
        m_cur.iter_mut().for_each(|v| *v = 0.0);
        let mut m0 = [
            problem.e_lat,
            problem.e_head,
            problem.yaw_rate_act,
            problem.speed_act,
        ];
        let stage = |k: usize| problem.stages[k.min(problem.stages.len() - 1)];
        for k in 0..n_p {
            let st = stage(k);
            let key = stage_key(&st);
            let phi = match cache.iter().find(|(ck, _)| *ck == key) {
                Some((_, e)) => *e,
                None => {
                    let e = discretise(key, p);
                    if cache.len() >= CACHE_LEN {
                        cache.remove(0);
                    }
                    cache.push((key, e));
                    e
                }
            };
            let j = k.min(n_c - 1);
            // M_(k+1) = A_d M_k + B_d E_j;  m_(k+1) = A_d m_k + w_y,k · b_w.
            for r in 0..NZ {
                for col in 0..nv {
                    let mut acc = 0.0;
                    for q in 0..NZ {
                        acc += phi[(r, q)] * m_cur[q * nv + col];
                    }
                    m_next[r * nv + col] = acc;
                }
                m_next[r * nv + 2 * j] += phi[(r, 4)];
                m_next[r * nv + 2 * j + 1] += phi[(r, 5)];
            }
            let mut m1 = [0.0; NZ];
            for (r, out) in m1.iter_mut().enumerate() {
                *out = (0..NZ).map(|q| phi[(r, q)] * m0[q]).sum::<f64>() + st.drift * phi[(r, 6)];
            }
            m0 = m1;
            std::mem::swap(m_cur, m_next);

            // Input cost at stage k (on the blocked input j).
            let ref_w = st.curvature * st.efficiency * p.speed_mps;
            h[(2 * j) * nv + 2 * j] += 2.0 * p.r_yaw_rate;
            f[2 * j] -= 2.0 * p.r_yaw_rate * ref_w;
            h[(2 * j + 1) * nv + 2 * j + 1] += 2.0 * p.r_speed;
            f[2 * j + 1] -= 2.0 * p.r_speed * p.speed_mps;

            // State cost at stage k + 1.
            let next = stage(k + 1);
            let w = stage_weights(next.curvature, p);
            let fac = if k + 1 == n_p { p.terminal_factor } else { 1.0 };
            let a = (next.efficiency * p.speed_mps).max(1e-6);
            let crab = (-next.drift / a).clamp(-0.3, 0.3);
            add_row_cost(h, f, &m_cur[0..nv], fac * w.q_lat, m0[0]);
            add_row_cost(h, f, &m_cur[nv..2 * nv], fac * w.q_head, m0[1] - crab);
        }
        // Input-rate costs.
        for j in 0..n_c {
            let rd_w = stage_weights(stage(j).curvature, p).rd_yaw_rate;
            for (off, rd, prev) in [
                (0, rd_w, problem.prev.yaw_rate),
                (1, p.rd_speed, problem.prev.speed),
            ] {
                let i = 2 * j + off;
                h[i * nv + i] += 2.0 * rd;
                if j == 0 {
                    f[i] -= 2.0 * rd * prev;
                } else {
                    let i0 = i - 2;
                    h[i0 * nv + i0] += 2.0 * rd;
                    h[i * nv + i0] -= 2.0 * rd;
                    h[i0 * nv + i] -= 2.0 * rd;
                }
            }
        }
    }

    fn build_bounds(&mut self, prev: Command) {
        let p = &self.params;
        let dw = p.max_yaw_accel_radps2 * p.control_period_s;
        let dv = p.max_accel_mps2 * p.control_period_s;
        for j in 0..self.n_c {
            let r0 = ROWS_PER_BLOCK * j;
            let (pw, pv) = if j == 0 {
                (prev.yaw_rate, prev.speed)
            } else {
                (0.0, 0.0)
            };
            self.b[r0] = p.max_speed_mps;
            self.b[r0 + 1] = -p.min_speed_mps;
            self.b[r0 + 2] = 0.0;
            self.b[r0 + 3] = 0.0;
            self.b[r0 + 4] = dw + pw;
            self.b[r0 + 5] = dw - pw;
            self.b[r0 + 6] = dv + pv;
            self.b[r0 + 7] = dv - pv;
        }
    }

    /// Solves the QP held in `p_vals`, `f`, `b`; returns the primal solution on success.
    ///
    /// Fast settings first (no equilibration, no iterative refinement: the problem is tiny and
    /// well scaled, and this halves the solve time); on failure one retry with Clarabel's robust
    /// defaults (equilibration + iterative refinement) before giving up.
    fn solve(&mut self) -> Option<Vec<f64>> {
        if let Some(x) = self.solve_with(false) {
            return Some(x);
        }
        self.solver = None;
        let x = self.solve_with(true);
        // Back to the fast solver at the next step.
        self.solver = None;
        x
    }

    fn solve_with(&mut self, robust: bool) -> Option<Vec<f64>> {
        if self.solver_robust != robust {
            self.solver = None;
        }
        if let Some(solver) = self.solver.as_mut() {
            let ok = solver.update_P(&self.p_vals).is_ok()
                && solver.update_q(&self.f).is_ok()
                && solver.update_b(&self.b).is_ok();
            if !ok {
                self.solver = None;
            }
        }
        if self.solver.is_none() {
            let settings = DefaultSettings::<f64> {
                verbose: false,
                max_iter: self.params.qp_max_iter,
                tol_gap_abs: self.params.qp_tolerance,
                tol_gap_rel: self.params.qp_tolerance,
                tol_feas: self.params.qp_tolerance,
                // Data updates need the problem structure untouched.
                presolve_enable: false,
                input_sparse_dropzeros: false,
                iterative_refinement_enable: robust,
                equilibrate_enable: robust,
                ..DefaultSettings::default()
            };
            let pm = CscMatrix::new(
                self.nv,
                self.nv,
                self.p_colptr.clone(),
                self.p_rowval.clone(),
                self.p_vals.clone(),
            );
            let cones = [SupportedConeT::NonnegativeConeT(self.n_con)];
            self.solver =
                DefaultSolver::new(&pm, &self.f, &self.a_mat, &self.b, &cones, settings).ok();
            self.solver_robust = robust;
        }
        let solver = self.solver.as_mut()?;
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved
                if solver.solution.x.iter().all(|v| v.is_finite()) =>
            {
                Some(solver.solution.x.clone())
            }
            _ => None,
        }
    }
}

/// Adds w·(r·U + c)² to ½UᵀHU + fᵀU, i.e. H += 2w·rᵀr and f += 2wc·r.
fn add_row_cost(h: &mut [f64], f: &mut [f64], r: &[f64], w: f64, c: f64) {
    if w == 0.0 {
        return;
    }
    let nv = r.len();
    for a in 0..nv {
        if r[a] == 0.0 {
            continue;
        }
        f[a] += 2.0 * w * c * r[a];
        for b in 0..nv {
            h[a * nv + b] += 2.0 * w * r[a] * r[b];
        }
    }
}

/// Projects `cmd` on the limits. With `rates`, also on the rate limits around `prev`:
///   v ∈ [v_min, v_max] ∩ [v_prev − a_max T, v_prev + a_max T],
///   ω ∈ [−c v, c v] ∩ [ω_prev − α_max T, ω_prev + α_max T]  (c = (1 + m)/R_min);
/// when an intersection is empty the absolute limit wins.
pub fn project_command(cmd: Command, prev: Command, p: &TrackingParams, rates: bool) -> Command {
    let c = p.max_curvature();
    let (mut vlo, mut vhi) = (p.min_speed_mps, p.max_speed_mps);
    if rates {
        let dv = p.max_accel_mps2 * p.control_period_s;
        let (lo, hi) = (vlo.max(prev.speed - dv), vhi.min(prev.speed + dv));
        if lo <= hi {
            (vlo, vhi) = (lo, hi);
        }
    }
    let speed = if cmd.speed.is_finite() {
        cmd.speed.clamp(vlo, vhi)
    } else {
        vlo
    };
    let (mut wlo, mut whi) = (-c * speed, c * speed);
    if rates {
        let dw = p.max_yaw_accel_radps2 * p.control_period_s;
        let (lo, hi) = (wlo.max(prev.yaw_rate - dw), whi.min(prev.yaw_rate + dw));
        if lo <= hi {
            (wlo, whi) = (lo, hi);
        }
    }
    let yaw_rate = if cmd.yaw_rate.is_finite() {
        cmd.yaw_rate.clamp(wlo, whi)
    } else {
        0.0
    };
    Command { yaw_rate, speed }
}

#[cfg(test)]
mod tests;
