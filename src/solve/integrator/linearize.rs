//! The linearized equations of motion at the current state, for modes and Floquet analysis.

use super::Integrator;
use crate::runtime::TangentCoeffs;

/// The linearized equations at the current state, dense, over the non-multiplier unknowns
/// (physical layout: virtual rotations): `M x'' + G x' + K x = 0` subject to `B x = 0`.
pub struct Linearization {
    /// The non-multiplier unknowns, in order.
    pub unknowns: Vec<usize>,
    pub m: Vec<f64>,
    pub g: Vec<f64>,
    pub k: Vec<f64>,
    /// Constraint rows (one per multiplier), row-major over `unknowns`.
    pub b: Vec<f64>,
    pub rows: usize,
}

impl Integrator<'_> {
    /// The element matrices at the current state (after `initialize`): mass, gyroscopic and
    /// damping, stiffness (elastic, inertial, and the constraint forces' geometric stiffness),
    /// and the constraint gradient (rate rows included: a driven coordinate is not perturbed).
    pub fn linearize(&mut self) -> Linearization {
        let n = self.sys.len();
        let free: Vec<usize> = (0..n).filter(|&i| !self.is_mult(i)).collect();
        let mults: Vec<usize> = (0..n).filter(|&i| self.is_mult(i)).collect();
        let mut col = vec![usize::MAX; n];
        for (j, &i) in free.iter().enumerate() {
            col[i] = j;
        }
        let nf = free.len();
        let aug = self.aug;
        let st = self.cur.clone();
        let mut dense = |c: TangentCoeffs, rows: &[usize]| -> Vec<f64> {
            self.asm.tangent(self.sys, &st, aug, c);
            let p = &self.asm.pattern;
            let mut out = vec![0.0; rows.len() * nf];
            let mut row_of = vec![usize::MAX; n];
            for (r, &i) in rows.iter().enumerate() {
                row_of[i] = r;
            }
            for j in 0..n {
                if col[j] == usize::MAX {
                    continue;
                }
                for s in p.col_ptr[j]..p.col_ptr[j + 1] {
                    let i = p.row_idx[s];
                    if row_of[i] != usize::MAX {
                        out[row_of[i] * nf + col[j]] = self.asm.values[s];
                    }
                }
            }
            out
        };
        let coeffs = |mass: f64, velocity: f64, position: f64| TangentCoeffs {
            mass,
            velocity,
            position,
            force_weight: 1.0,
        };
        let m = dense(coeffs(1.0, 0.0, 0.0), &free);
        let g = dense(coeffs(0.0, 1.0, 0.0), &free);
        let k = dense(coeffs(0.0, 0.0, 1.0), &free);
        let mut b = dense(coeffs(0.0, 1.0, 0.0), &mults);
        b.iter_mut().for_each(|x| *x /= aug.s);
        Linearization {
            unknowns: free,
            m,
            g,
            k,
            b,
            rows: mults.len(),
        }
    }
}
