//! Quadrature on a beam element: Gauss points on [-1, 1], the Lagrange shape functions on
//! equally spaced nodes, and what each point carries (weights, reference strains, the section).

use super::MAXN;
use serde::{Deserialize, Serialize};

/// One quadrature point: weight times Jacobian, shape functions and their arc-length
/// derivatives, the reference strains `(gamma*_0, kappa*_0)` and the section there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gauss {
    pub wj: f64,
    pub n: [f64; MAXN],
    pub dn: [f64; MAXN],
    pub strain0: [f64; 6],
    pub section: SectionAt,
}

/// A section's properties at a point, in the section frame: the stiffness (forces, then
/// moments), the mass per length, the centre-of-mass offset and the inertia per length about
/// the reference line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SectionAt {
    pub stiffness: [[f64; 6]; 6],
    pub mass: f64,
    pub eta: [f64; 3],
    pub rho: [[f64; 3]; 3],
}

/// The coordinates on [-1, 1] of the inertial points of an element of `nodes` nodes, in the
/// order of [`super::BeamElement::inertial`] (the lowering evaluates distributed loads there).
pub fn inertial_points(nodes: usize) -> &'static [f64] {
    gauss(nodes).0
}

/// Gauss points and weights on [-1, 1] for 1 to 4 points.
pub(super) fn gauss(n: usize) -> (&'static [f64], &'static [f64]) {
    const X1: [f64; 1] = [0.0];
    const W1: [f64; 1] = [2.0];
    const X2: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];
    const W2: [f64; 2] = [1.0, 1.0];
    const X3: [f64; 3] = [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4];
    const W3: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    const X4: [f64; 4] = [
        -0.861_136_311_594_052_6,
        -0.339_981_043_584_856_3,
        0.339_981_043_584_856_3,
        0.861_136_311_594_052_6,
    ];
    const W4: [f64; 4] = [
        0.347_854_845_137_453_9,
        0.652_145_154_862_546_1,
        0.652_145_154_862_546_1,
        0.347_854_845_137_453_9,
    ];
    match n {
        1 => (&X1, &W1),
        2 => (&X2, &W2),
        3 => (&X3, &W3),
        _ => (&X4, &W4),
    }
}

/// Lagrange shape functions and their derivatives on equally spaced nodes of [-1, 1].
pub fn shape(nn: usize, xi: f64) -> ([f64; MAXN], [f64; MAXN]) {
    let nodes: Vec<f64> = (0..nn)
        .map(|k| -1.0 + 2.0 * k as f64 / (nn - 1) as f64)
        .collect();
    let mut n = [0.0; MAXN];
    let mut dn = [0.0; MAXN];
    for k in 0..nn {
        let mut v = 1.0;
        let mut d = 0.0;
        for j in 0..nn {
            if j == k {
                continue;
            }
            let den = nodes[k] - nodes[j];
            // Product rule: d/dxi of prod (xi - x_j) / den.
            d = d * (xi - nodes[j]) / den + v / den;
            v *= (xi - nodes[j]) / den;
        }
        n[k] = v;
        dn[k] = d;
    }
    (n, dn)
}
