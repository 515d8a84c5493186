//! Elements: each reports its unknowns, residual and tangent.
//!
//! Local tangent matrices are dense, row-major, over the element's `indices()` in order.

use super::{Augment, Residual, State, TangentCoeffs};
use serde::{Deserialize, Serialize};

/// One end of a joint: a point fixed in the inertial frame, or a point mass.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "anchor", rename_all = "snake_case")]
pub enum Anchor {
    Fixed { point: [f64; 3] },
    Node { dofs: [usize; 3] },
}

impl Anchor {
    fn position(&self, st: &State) -> [f64; 3] {
        match self {
            Anchor::Fixed { point } => *point,
            Anchor::Node { dofs } => dofs.map(|i| st.q[i]),
        }
    }

    fn velocity(&self, st: &State) -> [f64; 3] {
        match self {
            Anchor::Fixed { .. } => [0.0; 3],
            Anchor::Node { dofs } => dofs.map(|i| st.v[i]),
        }
    }
}

/// Which time derivative of a constraint to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rate {
    /// `B v` (the velocity constraint).
    Velocity,
    /// `dB/dt v`: with `B a`, the second time derivative of `C`.
    AccelerationBias,
}

/// The closed set of elements.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "element", rename_all = "snake_case")]
pub enum Element {
    /// A point mass with its weight. Residual rows: `m a` (inertia) and `-m g` (force).
    PointMass {
        dofs: [usize; 3],
        mass: f64,
        gravity: [f64; 3],
    },
    /// Distance joint `C = |x_b - x_a| - L` with one multiplier; the force
    /// `mu = s lambda + p C` acts along `n = (x_b - x_a)/|x_b - x_a|`, pulling the ends
    /// together when positive (tension). THEORY §5, §6.
    Distance {
        a: Anchor,
        b: Anchor,
        length: f64,
        multiplier: usize,
    },
}

impl Element {
    /// The unknowns this element couples, in local order.
    pub fn indices(&self) -> Vec<usize> {
        match self {
            Element::PointMass { dofs, .. } => dofs.to_vec(),
            Element::Distance {
                a, b, multiplier, ..
            } => {
                let mut v = Vec::with_capacity(7);
                for end in [a, b] {
                    if let Anchor::Node { dofs } = end {
                        v.extend_from_slice(dofs);
                    }
                }
                v.push(*multiplier);
                v
            }
        }
    }

    pub fn translational_mass(&self) -> Option<f64> {
        match self {
            Element::PointMass { mass, .. } => Some(*mass),
            Element::Distance { .. } => None,
        }
    }

    /// Adds this element's residual contributions.
    pub fn residual(&self, st: &State, aug: Augment, r: &mut Residual) {
        match self {
            Element::PointMass {
                dofs,
                mass,
                gravity,
            } => {
                for k in 0..3 {
                    r.inertia[dofs[k]] += mass * st.a[dofs[k]];
                    r.force[dofs[k]] -= mass * gravity[k];
                }
            }
            Element::Distance {
                a,
                b,
                length,
                multiplier,
            } => {
                let g = DistanceGeometry::new(a.position(st), b.position(st));
                let c = g.len - length;
                let mu = aug.s * st.lambda[*multiplier] + aug.p * c;
                for (end, sign) in [(a, -1.0), (b, 1.0)] {
                    if let Anchor::Node { dofs } = end {
                        for k in 0..3 {
                            r.force[dofs[k]] += sign * g.n[k] * mu;
                        }
                    }
                }
                r.constraint[*multiplier] = c;
            }
        }
    }

    /// Writes the local tangent (row-major, `indices().len()` squared) into `k`.
    pub fn tangent(&self, st: &State, aug: Augment, c: TangentCoeffs, k: &mut [f64]) {
        match self {
            Element::PointMass { mass, .. } => {
                k[..9].iter_mut().for_each(|x| *x = 0.0);
                for i in 0..3 {
                    k[i * 3 + i] = c.mass * mass;
                }
            }
            Element::Distance {
                a,
                b,
                length,
                multiplier,
            } => {
                let nodes = [a, b]
                    .iter()
                    .filter(|e| matches!(e, Anchor::Node { .. }))
                    .count();
                let nl = 3 * nodes + 1;
                k[..nl * nl].iter_mut().for_each(|x| *x = 0.0);
                let g = DistanceGeometry::new(a.position(st), b.position(st));
                let cv = g.len - length;
                let mu = aug.s * st.lambda[*multiplier] + aug.p * cv;
                // d(n mu)/dx_b = p n n^T + mu (I - n n^T)/len  (penalty + geometric stiffness)
                let mut kb = [[0.0; 3]; 3];
                for i in 0..3 {
                    for j in 0..3 {
                        let delta = if i == j { 1.0 } else { 0.0 };
                        kb[i][j] = c.force_weight
                            * c.position
                            * (aug.p * g.n[i] * g.n[j] + mu * (delta - g.n[i] * g.n[j]) / g.len);
                    }
                }
                // Local offsets and signs of the moving ends (no allocation on this hot path).
                let mut ends = [(0usize, 0.0f64); 2];
                let mut count = 0;
                for (end, sign) in [(a, -1.0), (b, 1.0)] {
                    if let Anchor::Node { .. } = end {
                        ends[count] = (3 * count, sign);
                        count += 1;
                    }
                }
                let ends = &ends[..count];
                let m = nl - 1;
                for &(oi, si) in ends {
                    for &(oj, sj) in ends {
                        for i in 0..3 {
                            for j in 0..3 {
                                k[(oi + i) * nl + oj + j] += si * sj * kb[i][j];
                            }
                        }
                    }
                    for i in 0..3 {
                        k[(oi + i) * nl + m] = c.force_weight * aug.s * si * g.n[i];
                        k[m * nl + oi + i] = aug.s * si * g.n[i];
                    }
                }
            }
        }
    }

    /// Writes a time derivative of the constraints into `out` at multiplier rows.
    pub fn constraint_rate(&self, st: &State, rate: Rate, out: &mut [f64]) {
        if let Element::Distance {
            a, b, multiplier, ..
        } = self
        {
            let g = DistanceGeometry::new(a.position(st), b.position(st));
            let (va, vb) = (a.velocity(st), b.velocity(st));
            let dv = [vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]];
            let ndv = dot(g.n, dv);
            out[*multiplier] = match rate {
                Rate::Velocity => ndv,
                // d/dt (n . v) with v fixed: (|dv|^2 - (n . dv)^2) / len
                Rate::AccelerationBias => (dot(dv, dv) - ndv * ndv) / g.len,
            };
        }
    }

    /// Physical constraint force of multiplier row `row`.
    pub fn constraint_force(&self, st: &State, aug: Augment, row: usize) -> f64 {
        match self {
            Element::Distance { multiplier, .. } => {
                aug.s * st.lambda[*multiplier + row] + aug.p * self.violation(st, row)
            }
            Element::PointMass { .. } => 0.0,
        }
    }

    pub fn violation(&self, st: &State, _row: usize) -> f64 {
        match self {
            Element::Distance { a, b, length, .. } => {
                DistanceGeometry::new(a.position(st), b.position(st)).len - length
            }
            Element::PointMass { .. } => 0.0,
        }
    }
}

struct DistanceGeometry {
    len: f64,
    n: [f64; 3],
}

impl DistanceGeometry {
    fn new(xa: [f64; 3], xb: [f64; 3]) -> DistanceGeometry {
        let d = [xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]];
        let len = dot(d, d).sqrt();
        // A zero length is rejected by the compiler; guard the division anyway.
        let inv = if len > 0.0 { 1.0 / len } else { 0.0 };
        DistanceGeometry {
            len,
            n: d.map(|x| x * inv),
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator, so the property test needs no extra crate.
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    /// The analytic tangent of the distance joint against central differences of its residual,
    /// over random configurations, multipliers, scalings and coefficients, with both ends
    /// moving or one end fixed. Relative agreement 1e-6 (central differences, h = 1e-6).
    #[test]
    fn distance_tangent_matches_finite_differences() {
        let mut rng = Lcg(42);
        for case in 0..200 {
            let fixed = case % 3 == 0;
            let a = if fixed {
                Anchor::Fixed {
                    point: [rng.next(), rng.next(), rng.next()],
                }
            } else {
                Anchor::Node { dofs: [0, 1, 2] }
            };
            let el = Element::Distance {
                a,
                b: Anchor::Node { dofs: [3, 4, 5] },
                length: 0.5 + rng.next().abs(),
                multiplier: 6,
            };
            let mut st = State::zeros(7);
            st.q.iter_mut().take(6).for_each(|q| *q = rng.next());
            st.lambda[6] = rng.next();
            let aug = Augment {
                s: 1.0 + 10.0 * rng.next().abs(),
                p: 1.0 + 10.0 * rng.next().abs(),
            };
            let c = TangentCoeffs {
                mass: 0.0,
                velocity: 0.0,
                position: 1.0,
                force_weight: 0.9 + 0.1 * rng.next().abs(),
            };
            let idx = el.indices();
            let nl = idx.len();
            let mut k = vec![0.0; nl * nl];
            el.tangent(&st, aug, c, &mut k);
            // The residual as the integrator forms it: weighted forces, scaled constraint.
            let full = |st: &State| {
                let mut r = Residual::new(7);
                el.residual(st, aug, &mut r);
                let mut out: Vec<f64> = r.force.iter().map(|f| c.force_weight * f).collect();
                out[6] = aug.s * r.constraint[6];
                out
            };
            let h = 1e-6;
            for (lj, &j) in idx.iter().enumerate() {
                let (mut sp, mut sm) = (st.clone(), st.clone());
                if j < 6 {
                    sp.q[j] += h;
                    sm.q[j] -= h;
                } else {
                    sp.lambda[j] += h;
                    sm.lambda[j] -= h;
                }
                let (rp, rm) = (full(&sp), full(&sm));
                for (li, &i) in idx.iter().enumerate() {
                    let fd = (rp[i] - rm[i]) / (2.0 * h);
                    let an = k[li * nl + lj];
                    assert!(
                        (fd - an).abs() < 1e-6 * (1.0 + fd.abs()),
                        "case {case}: K[{i}][{j}] = {an} vs fd {fd}"
                    );
                }
            }
        }
    }
}
