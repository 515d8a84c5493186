//! The iteration matrix against central differences of the residual over the corrections
//! themselves (body-frame increments composed into each frame), in the middle of a motion.

use super::{Integrator, Predictor};
use crate::runtime::Augment;
use crate::settings::Request;

/// A model of `models/` compiled with `sets` and `request`.
fn compiled(model: &str, sets: &[String], request: Request) -> crate::Compiled {
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/models/{model}.mbd")).unwrap();
    crate::compile(model, &text, sets, request)
        .map_err(|_| "compile")
        .unwrap()
}

/// The model's integrator after `steps` steps from its consistent start.
fn advanced(c: &crate::Compiled, steps: usize) -> Integrator<'_> {
    let sys = &c.lowered.system;
    let mut it = Integrator::new(sys, &c.settings)
        .map_err(|f| f.detail)
        .unwrap();
    it.initialize().map_err(|f| f.detail).unwrap();
    for _ in 0..steps {
        it.attempt(c.settings.dt).map_err(|f| f.detail).unwrap();
    }
    it
}

impl Integrator<'_> {
    /// The largest difference between the exact iteration matrix at the iterate (beam nodes'
    /// rate columns included, as the step's tangent takes it) and central differences of
    /// `T^T r` (rows at the iterate's `T`), relative to the largest entry of its column.
    fn matrix_error(&mut self, h: f64, aug: Augment) -> f64 {
        let n = self.sys.len();
        let (trial0, q0, f0) = (
            self.trial.clone(),
            self.step_q.clone(),
            self.step_frames.clone(),
        );
        self.newmark_residual(aug, 1.0)
            .map_err(|f| f.detail)
            .unwrap();
        self.exact_rates = true;
        self.newmark_matrix(h, aug);
        self.exact_rates = false;
        let (mats, p) = (self.mats.clone(), self.asm.pattern.clone());
        let mut dense = vec![0.0; n * n];
        for c in 0..n {
            for s in p.col_ptr[c]..p.col_ptr[c + 1] {
                dense[p.row_idx[s] * n + c] = self.asm.values[s];
            }
        }
        let largest = dense.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let eps = 1e-5;
        let mut worst = 0.0f64;
        for j in 0..n {
            let mut cols = [vec![], vec![]];
            for (s, sign) in [(0, 1.0), (1, -1.0)] {
                self.trial.assign(&trial0);
                self.step_q.copy_from_slice(&q0);
                self.step_frames.copy_from_slice(&f0);
                self.rhs.iter_mut().for_each(|x| *x = 0.0);
                self.rhs[j] = sign * eps;
                self.newmark_correct(h);
                self.asm.residual(self.sys, &self.trial, aug);
                let r = &self.asm.residual;
                let mut out: Vec<f64> = (0..n)
                    .map(|i| match self.sys.unknowns[i].is_multiplier() {
                        true => aug.s * r.constraint[i],
                        false => r.inertia[i] + r.force[i],
                    })
                    .collect();
                super::rotations::transform_vector(&self.blocks, &mats, &mut out);
                cols[s] = out;
            }
            // Each column against its own largest entry: a beam's stiffness would hide the
            // inertial columns' errors (measured 3e-4 on the rotating beam without the beam
            // nodes' rate columns).
            let (mut error, mut size) = (0.0f64, 0.0f64);
            for i in 0..n {
                let fd = (cols[0][i] - cols[1][i]) / (2.0 * eps);
                error = error.max((fd - dense[i * n + j]).abs());
                size = size.max(dense[i * n + j].abs());
            }
            // (Columns below 1e-6 of the largest entry: central differences' round-off.)
            worst = worst.max(error / size.max(1e-6 * largest));
        }
        self.trial.assign(&trial0);
        worst
    }
}

/// Rigid frames in large motion (the two-bar at 0.05 s, bar 2 spinning; the windmill's rotor
/// and tower): the SE(3) columns with the rates' exact dependence on the correction.
/// Measured 6.8e-11 and 6.7e-11 relative to each column (central differences' round-off);
/// the columns before, `R J_r^-1` on every term, were 1e-5 (two-bar) and 2e-3 (windmill)
/// off. Beam nodes with their rate columns (the step's tangent): the elastic windmill 6.7e-11,
/// the rotating beam (rotary inertia) 1.4e-10, 3e-4 without them; the two-bar of beams a
/// million times stiffer than the bars, 1.2e-6 (round-off of its stiffness).
#[test]
fn the_iteration_matrix_of_frames_is_the_residuals_derivative() {
    for (model, steps, bound) in [
        ("two_bar", 100, 2e-10),
        ("windmill", 400, 2e-10),
        ("two_bar_spin_elastic", 50, 4e-6),
        ("windmill_elastic", 50, 2e-10),
        ("rotating_beam", 20, 4e-10),
    ] {
        let c = compiled(model, &[], Request::default());
        let mut it = advanced(&c, steps);
        let h = c.settings.dt;
        let aug = it.scaling(h);
        it.newmark_predict(h, 1.0, false, Predictor::Acceleration);
        let e = it.matrix_error(h, aug);
        eprintln!("{model}: iteration matrix vs central differences {e:.2e}");
        assert!(e < bound, "{model}: {e:.3e} exceeds {bound:.1e}");
    }
}

impl Integrator<'_> {
    /// The trial state from `cur` and the step's increments, its rates by the Newmark relations.
    fn place(&mut self, h: f64) {
        self.trial.assign(&self.cur);
        let (cur, tr) = (&self.cur, &mut self.trial);
        for i in 0..self.sys.len() {
            if !self.in_frame[i] && !self.sys.unknowns[i].is_multiplier() {
                tr.q[i] = cur.q[i] + self.step_q[i];
            }
        }
        for k in 0..self.sys.rotations.len() {
            super::se3::displace(self.sys, cur, tr, k, &self.step_frames[k]);
        }
        self.rates_from_increments(h);
    }

    /// The trial state's rates from the step's increments by the Newmark relations.
    fn rates_from_increments(&mut self, h: f64) {
        let sc = self.sc;
        let (cur, tr) = (&self.cur, &mut self.trial);
        for i in 0..self.sys.len() {
            if !self.in_frame[i] && !self.sys.unknowns[i].is_multiplier() {
                let (v, a, alg) = sc.relation(h, self.step_q[i], cur.v[i], cur.a[i], cur.alg[i]);
                (tr.v[i], tr.a[i], tr.alg[i]) = (v, a, alg);
            }
        }
        for k in 0..self.sys.rotations.len() {
            let (d, f0, f) = (self.step_frames[k], cur.frames[k], &mut tr.frames[k]);
            for j in 0..6 {
                (f.v[j], f.dv[j], f.alg[j]) = sc.relation(h, d[j], f0.v[j], f0.dv[j], f0.alg[j]);
            }
            super::se3::to_physical(self.sys, tr, k);
        }
    }

    /// The step's map at its converged increment, `T dir` and `D x`, against central
    /// differences of the step's own functions (`newmark`, `se3::displace`, `se3::compose`):
    /// the largest difference relative to the largest entry, over a few directions.
    fn map_error(&mut self, h: f64) -> f64 {
        let n = self.sys.len();
        let (start, q0, f0) = (
            self.cur.clone(),
            self.step_q.clone(),
            self.step_frames.clone(),
        );
        // The step from `start`: its end.
        self.place(h);
        let end = self.trial.clone();
        let mut nodes = vec![super::tangent::NodeMap::default(); self.sys.rotations.len()];
        self.node_maps(&mut nodes);
        let mut worst = 0.0f64;
        let mut largest = 0.0f64;
        let (mut analytic, mut plus, mut minus) =
            (vec![0.0; 4 * n], vec![0.0; 4 * n], vec![0.0; 4 * n]);
        for seed in 0..4u64 {
            // A direction of the start (every slot), and a correction of the increment.
            let pseudo = |i: usize| {
                let x = ((i as u64 + 1) * 2654435761 + seed * 97) % 1000;
                x as f64 / 500.0 - 1.0
            };
            let mut dir: Vec<f64> = (0..4 * n).map(pseudo).collect();
            let x: Vec<f64> = (0..n).map(|i| pseudo(i + 7)).collect();
            for i in 0..n {
                if self.sys.unknowns[i].is_multiplier() {
                    for b in 0..4 {
                        dir[b * n + i] = 0.0;
                    }
                }
            }
            let coef = self.coefficients(h);
            self.transport(&coef, &nodes, &dir, &mut analytic);
            self.correct(&coef, &nodes, &x, &mut analytic);
            let eps = 1e-6;
            for (sign, out) in [(1.0, &mut plus), (-1.0, &mut minus)] {
                let e = sign * eps;
                super::tangent::perturb(self.sys, &self.in_frame, &start, &dir, e, &mut self.cur);
                for i in 0..n {
                    self.step_q[i] = q0[i] + e * x[i];
                }
                for k in 0..self.sys.rotations.len() {
                    let (t, r) = (self.sys.translations[k], self.sys.rotations[k]);
                    let d: [f64; 6] = std::array::from_fn(|j| match j {
                        0..=2 if self.sys.is_frame(k) => e * x[t + j],
                        0..=2 => 0.0,
                        _ => e * x[r + j - 3],
                    });
                    self.step_frames[k] = super::se3::compose(self.sys, k, &f0[k], &d);
                }
                self.place(h);
                super::tangent::difference(self.sys, &self.in_frame, &self.trial, &end, out);
            }
            for i in 0..4 * n {
                let fd = (plus[i] - minus[i]) / (2.0 * eps);
                worst = worst.max((fd - analytic[i]).abs());
                largest = largest.max(analytic[i].abs());
            }
        }
        self.cur.assign(&start);
        self.step_q.copy_from_slice(&q0);
        self.step_frames.copy_from_slice(&f0);
        worst / largest
    }
}

/// The step's map at a fixed increment (`T`: a frame's start perturbation carried by
/// `Ad(exp(-D))`, the rates by the Newmark relations) and its answer to a correction of the
/// increment (`D`: the increment's inverse right Jacobian), against central differences of
/// the step's own functions, on rigid frames (two-bar, windmill) and beam nodes (the
/// two-bar of elastic beams). Measured 2.0e-11, 1.5e-12 and 1.7e-13 relative.
#[test]
fn the_steps_map_is_the_derivative_of_the_step() {
    for (model, steps, bound) in [
        ("two_bar", 100, 6e-11),
        ("windmill", 400, 5e-12),
        ("two_bar_spin_elastic", 50, 5e-13),
    ] {
        let c = compiled(model, &[], Request::default());
        let mut it = advanced(&c, steps);
        // The last step's increments, from the state before it.
        let h = c.settings.dt;
        it.cur.assign(&it.trial.clone());
        let e = it.map_error(h);
        eprintln!("{model}: the step's map vs central differences {e:.2e}");
        assert!(e < bound, "{model}: {e:.3e} exceeds {bound:.1e}");
    }
}

/// One step's tangent carried by `propagate` (the exact iteration matrix, the residual's
/// derivative along the direction's rates) against central differences of whole steps, Newton
/// converged to 1e-13 from either perturbed start, along a direction with every slot of the
/// state set, carried alone and among copies of it. Measured 1.1e-9 (windmill; 3.6e-9 with
/// its bodies' rates by differences, before their assembled derivatives were taken for any
/// number of directions), 2.2e-11 and 6.6e-12 (rotating beam mid-run and at the start; by
/// differences it was 2.5e-7 and 5.1e-7, their axial forces cancelling to round-off), 1.6e-9
/// (two-bar of beams).
#[test]
fn the_carried_direction_is_the_derivative_of_a_step() {
    for (model, sets, steps, bound) in [
        ("windmill", vec![], 400, 3.5e-9),
        ("rotating_beam", vec!["elements=2".to_string()], 20, 6.5e-11),
        ("rotating_beam", vec!["elements=2".to_string()], 0, 2e-11),
        ("two_bar_spin_elastic", vec![], 50, 5e-9),
    ] {
        let request = Request {
            tolerance: Some(1e-13),
            ..Request::default()
        };
        let c = compiled(model, &sets, request);
        let mut it = advanced(&c, steps);
        let (sys, h) = (it.sys, c.settings.dt);
        let n = sys.len();
        let start = it.cur.clone();
        let mut dir: Vec<f64> = (0..4 * n)
            .map(|i| ((i as u64 * 2654435761 + 13) % 1000) as f64 / 500.0 - 1.0)
            .collect();
        for i in 0..n {
            let scale = if sys.unknowns[i].is_multiplier() {
                0.0
            } else {
                1.0
            };
            for b in 0..4 {
                dir[b * n + i] *= scale * [1.0, 1.0, 1.0 / h, 1.0 / h][b];
            }
        }
        // Once alone, once among copies: the same column both ways.
        let copies = 3;
        it.track(dir.repeat(copies), 1.0);
        it.advance(h, 0).map_err(|f| f.detail).unwrap();
        let many = it.tracked().unwrap()[..4 * n].to_vec();
        it.cur.assign(&start);
        it.track(dir.clone(), 1.0);
        it.advance(h, 0).map_err(|f| f.detail).unwrap();
        let carried = it.tracked().unwrap().to_vec();
        let end = it.cur.clone();

        it.tracked = None;
        let eps = 1e-6;
        let mut diffs = [vec![0.0; 4 * n], vec![0.0; 4 * n]];
        for (s, sign) in [(0, 1.0), (1, -1.0)] {
            let mut st = start.clone();
            super::tangent::perturb(sys, &it.in_frame, &start, &dir, sign * eps, &mut st);
            it.cur.assign(&st);
            it.attempt(h).map_err(|f| f.detail).unwrap();
            super::tangent::difference(sys, &it.in_frame, &it.cur, &end, &mut diffs[s]);
        }
        let (mut worst, mut largest) = ([0.0f64; 2], 0.0f64);
        for i in 0..4 * n {
            let fd = (diffs[0][i] - diffs[1][i]) / (2.0 * eps);
            worst[0] = worst[0].max((fd - carried[i]).abs());
            worst[1] = worst[1].max((fd - many[i]).abs());
            largest = largest.max(fd.abs());
        }
        let (alone, among) = (worst[0] / largest, worst[1] / largest);
        eprintln!("{model}: carried vs whole steps {alone:.2e} alone, {among:.2e} among many");
        let e = alone.max(among);
        assert!(e < bound, "{model}: {e:.3e} exceeds {bound:.1e}");
    }
}

/// The residual's derivative along a change of the rates alone, from the elements' rate
/// derivatives (`M da + C dv`, with the joints' rate rows by differences) as the step's
/// tangent takes it for many directions, against central differences of every element that
/// reads the rates (exact but for round-off: the residual is quadratic in the velocities and
/// linear in the accelerations: the differences' error goes as 1 / eps, their round-off).
/// Relative to the largest entry, measured 5.6e-16 (windmill), 4.3e-11 (rotating beam),
/// 9.8e-22 (spinning elastic two-bar).
#[test]
fn the_rate_derivatives_are_the_residuals_along_the_rates() {
    for (model, sets, steps, bound) in [
        ("windmill", vec![], 400, 1.7e-15),
        ("rotating_beam", vec!["elements=2".to_string()], 20, 1.3e-10),
        ("two_bar_spin_elastic", vec![], 50, 1.5e-21),
    ] {
        let c = compiled(model, &sets, Request::default());
        let mut it = advanced(&c, steps);
        let (sys, aug) = (it.sys, it.aug);
        let n = sys.len();
        // A direction of the rates alone (positions zero), scaled like the state's rates.
        let mut dir = vec![0.0; 4 * n];
        for i in (0..n).filter(|&i| !sys.unknowns[i].is_multiplier()) {
            for b in 1..4 {
                let x = ((((b * n + i) as u64) * 2654435761 + 7) % 1000) as f64 / 500.0 - 1.0;
                dir[b * n + i] = x * [0.0, 1.0, 10.0, 10.0][b];
            }
        }
        let cur = it.cur.clone();
        let (mut dv, mut da) = (vec![0.0; n], vec![0.0; n]);
        super::tangent::physical_rates(sys, &it.in_frame, &cur, (&dir, 1), (&mut dv, &mut da));
        it.asm.rate_jacobians(sys, &cur, aug);
        let mut analytic = vec![0.0; n];
        it.asm.rate_products(&dv, &da, 1, &mut analytic);
        // Several directions at once: the same products, column by column.
        let twice = |x: &[f64]| -> Vec<f64> { x.iter().chain(x).map(|v| v * 1.5).collect() };
        let mut batched = vec![0.0; 2 * n];
        it.asm
            .rate_products(&twice(&dv), &twice(&da), 2, &mut batched);
        for (k, b) in batched.iter().enumerate() {
            let a = 1.5 * analytic[k % n];
            assert!(
                (a - b).abs() <= 1e-14 * a.abs().max(1.0),
                "{model}: {k}: {a} vs {b}"
            );
        }
        let row = |r: &crate::runtime::Residual, i: usize| {
            if sys.unknowns[i].is_multiplier() {
                aug.s * r.constraint[i]
            } else {
                r.inertia[i] + r.force[i]
            }
        };
        let eps = 1e-2;
        let mut st = cur.clone();
        let mut ends = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let every: (Vec<usize>, Vec<usize>) =
            ((0..n).collect(), (0..sys.rotations.len()).collect());
        for (k, (sign, all)) in [(1.0, true), (-1.0, true), (1.0, false), (-1.0, false)]
            .into_iter()
            .enumerate()
        {
            st.assign(&cur);
            let on = (every.0.as_slice(), every.1.as_slice());
            super::tangent::perturb_rates(sys, &it.in_frame, &cur, &dir, sign * eps, on, &mut st);
            // Rows outside the evaluated elements' unknowns are not written: zero them.
            it.asm.residual.clear();
            it.asm.rate_residual(sys, &st, aug, all);
            for i in 0..n {
                ends[k][i] = row(&it.asm.residual, i);
            }
        }
        let (mut worst, mut largest) = (0.0f64, 0.0f64);
        for i in 0..n {
            let fd = (ends[0][i] - ends[1][i]) / (2.0 * eps);
            let rest = (ends[2][i] - ends[3][i]) / (2.0 * eps);
            worst = worst.max((fd - analytic[i] - rest).abs());
            largest = largest.max(fd.abs());
        }
        let e = worst / largest;
        eprintln!("{model}: rate derivatives vs differences {e:.2e}");
        assert!(
            largest > 0.0 && e < bound,
            "{model}: {e:.3e} exceeds {bound:.1e}"
        );
    }
}

/// The elastic windmill, 2 elements per blade, in the ground-resonance band.
fn elastic_windmill() -> crate::Compiled {
    let sets = ["elements=2".to_string(), "Omega_bar=1.5".to_string()];
    compiled("windmill_elastic", &sets, Request::default())
}

/// `count` directions of the state layout, pseudo-random in `[-1, 1)` on the positions and
/// rates of the unknowns that are not multipliers, zero on the accelerations.
fn spread_directions(sys: &crate::runtime::System, count: usize) -> Vec<f64> {
    let n = sys.len();
    (0..4 * n * count)
        .map(|k| {
            let i = (k % (4 * n)) % n;
            if sys.unknowns[i].is_multiplier() || k % (4 * n) >= 2 * n {
                0.0
            } else {
                ((k as u64 * 2654435761 + 5) % 1000) as f64 / 500.0 - 1.0
            }
        })
        .collect()
}

/// The weight of slot `i` of a direction as deflation weighs it (time scale `tau`, steps of
/// `h`): positions over their scale (the length scale, 1 rad for rotations and angles), rates
/// times `tau`, accelerations times `h^2`.
fn state_weight(sys: &crate::runtime::System, tau: f64, h: f64) -> impl Fn(usize) -> f64 + '_ {
    let (n, angles) = (sys.len(), sys.angle_unknowns());
    move |i: usize| {
        let scale = match sys.unknowns[i % n] {
            crate::runtime::UnknownKind::Coordinate if !angles.contains(&(i % n)) => {
                sys.length_scale
            }
            _ => 1.0,
        };
        [1.0, tau, h * h, h * h][i / n] / scale
    }
}

/// Deflation (`deflate.rs`) against the same directions carried whole: on the elastic windmill
/// (2 elements per blade, stiff axial and shear modes), 160 directions over 400 steps, deflated
/// every 100; the given directions rebuilt from the carried ones and the map, weighted as the
/// deflation weighs them, relative to the largest. Measured 7.6e-10 with 59 of the 160 left.
#[test]
fn deflated_directions_rebuild_the_whole_ones() {
    let c = elastic_windmill();
    let mut it = advanced(&c, 20);
    let (sys, h, count) = (it.sys, c.settings.dt, 160);
    let (n, dirs) = (sys.len(), spread_directions(sys, count));
    let start = it.cur.clone();
    let carry = |it: &mut Integrator, every: usize| {
        it.cur.assign(&start);
        it.track(dirs.clone(), 0.1);
        it.deflate_every(every, false);
        for _ in 0..400 {
            it.advance(h, 0).map_err(|f| f.detail).unwrap();
        }
        let (cols, map) = (
            it.tracked().unwrap().to_vec(),
            it.tracked_map().unwrap().to_vec(),
        );
        (cols, map)
    };
    let (whole, _) = carry(&mut it, 0);
    let (cols, map) = carry(&mut it, 100);
    let kept = cols.len() / (4 * n);
    assert!(kept < count, "nothing deflated");
    let weight = state_weight(sys, 0.1, h);
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for g in 0..count {
        for i in 0..4 * n {
            let rebuilt: f64 = (0..kept)
                .map(|j| cols[j * 4 * n + i] * map[g * kept + j])
                .sum();
            let w = weight(i);
            worst = worst.max(((rebuilt - whole[g * 4 * n + i]) * w).abs());
            largest = largest.max((whole[g * 4 * n + i] * w).abs());
        }
    }
    let e = worst / largest;
    eprintln!("deflation: {kept} of {count} kept, rebuilt to {e:.2e}");
    assert!(e < 2.3e-9, "{e:.3e}");
}

/// The settled monodromy (`deflate.rs`: the directions orthonormal at the first pass, their
/// images read through the later passes' maps) against the same directions carried whole from
/// the settling step: the elastic windmill, 160 directions, deflated every 100 steps, 300 steps
/// on, in the same weights. Measured 4.7e-9 relative to the largest entry.
#[test]
fn the_settled_monodromy_is_the_settled_directions_carried_whole() {
    let c = elastic_windmill();
    let mut it = advanced(&c, 20);
    let (sys, h, count) = (it.sys, c.settings.dt, 160);
    let (n, dirs) = (sys.len(), spread_directions(sys, count));
    let tau = 0.1;
    it.track(dirs, tau);
    it.deflate_every(100, true);
    for _ in 0..100 {
        it.advance(h, 0).map_err(|f| f.detail).unwrap();
    }
    assert!(it.is_settled(), "the first pass settles");
    let settled = it.tracked.as_ref().unwrap().settled.clone();
    let at = it.cur.clone();
    for _ in 0..300 {
        it.advance(h, 0).map_err(|f| f.detail).unwrap();
    }
    let deflated = it.settled_monodromy().unwrap();
    // The same directions carried whole from the settling step.
    it.cur.assign(&at);
    it.track(settled.clone(), tau);
    for _ in 0..300 {
        it.advance(h, 0).map_err(|f| f.detail).unwrap();
    }
    let images = it.tracked().unwrap().to_vec();
    let weight = state_weight(sys, tau, h);
    let r = settled.len() / (4 * n);
    let u = nalgebra::DMatrix::from_fn(4 * n, r, |i, j| settled[j * 4 * n + i] * weight(i));
    let s = nalgebra::DMatrix::from_fn(4 * n, r, |i, j| images[j * 4 * n + i] * weight(i));
    let whole = u.transpose() * s;
    let e = (&deflated - &whole).amax() / whole.amax();
    eprintln!("settled monodromy: {r} directions, deflated against whole {e:.2e}");
    assert!(e < 1.5e-8, "{e:.3e}"); // 7.2e-9
}
