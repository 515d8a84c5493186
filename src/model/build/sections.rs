//! Sections: the 6x6 stiffness (whole or its diagonal, with per-block units), the mass per
//! length, its offset and inertias (or the whole 6x6 mass matrix), checked positive; declared
//! (`section NAME { ... }`), written in a beam, or named by one. Contract: builds `Section`s;
//! must not build beams.

use super::{Builder, Built, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::{self, Dim, Quantity};
use crate::model::eval::Value;
use crate::model::scope::env::Ref;
use crate::model::*;
use crate::syntax::ast::{Block, Prop, PropValue};
use std::collections::HashMap;

const BENDING: Quantity = Dim::new(1, 3, -2).quantity();

/// A 6x6 section matrix: its property, the dimension of its upper-left block (length and time
/// exponents over a mass; each of rows and columns 4-6 adds a length) and its hints.
struct Matrix6 {
    name: &'static str,
    length: i8,
    time: i8,
    shape: &'static str,
    units: &'static str,
}

const STIFFNESS: Matrix6 = Matrix6 {
    name: "stiffness",
    length: 1,
    time: -2,
    shape: "write `stiffness = ((EA, 0, 0, 0, 0, 0) N, ..., (0, 0, 0, 0, 0, EI3) N*m^2)`; rows and columns 1-3 in N, 4-6 in N*m, the lower-right block in N*m^2",
    units: "rows and columns 1-3 are forces (N), 4-6 moments (N*m): the blocks are N, N*m and N*m^2",
};

const MASS: Matrix6 = Matrix6 {
    name: "mass_matrix",
    length: -1,
    time: 0,
    shape: "write `mass_matrix = ((m, 0, 0, 0, 0, 0) kg/m, ..., (0, 0, 0, 0, 0, i3) kg*m)`; rows and columns 1-3 in kg/m, the coupling blocks in kg, the lower-right block in kg*m",
    units: "rows and columns 1-3 are per length (kg/m), the couplings kg, the inertias per length kg*m",
};

type Props = HashMap<&'static str, Prop>;

impl Builder<'_> {
    pub(super) fn section_decl(&mut self, v: &View) -> Option<Built> {
        if !self.shape(
            v,
            0,
            false,
            false,
            &[],
            "section NAME { EA = ..., EI2 = ..., mass_per_length = ... }",
        ) {
            return None;
        }
        let block = v.block.clone().unwrap_or_default();
        let s = self.section(v, &block, v.name.clone())?;
        self.sections.push(s);
        Some(Built::Section(self.sections.len() - 1))
    }

    pub(super) fn section(&mut self, v: &View, block: &Block, name: String) -> Option<Section> {
        let p = self.props(
            v.scope,
            Some(block),
            &[
                "EA",
                "GA2",
                "GA3",
                "GJ",
                "EI2",
                "EI3",
                "stiffness",
                "mass_per_length",
                "mass_offset2",
                "mass_offset3",
                "i2",
                "i3",
                "polar",
                "tension_offset2",
                "tension_offset3",
                "shear_offset2",
                "shear_offset3",
                "mass_matrix",
            ],
            "a section",
        );
        let (k, ok) = self.section_stiffness(v, block, &p)?;
        let mass = self.section_mass(v, block, &p);
        if !ok {
            return None;
        }
        let (mass, mass_offset, inertia) = mass?;
        let section = Section {
            name,
            stiffness: k,
            mass_per_length: mass,
            mass_offset,
            inertia,
        };
        self.check_section(v, block, &p, &section)
            .then_some(section)
    }

    /// The 6x6 stiffness, written whole or as its diagonal; `None` to stop at once, and
    /// whether every diagonal entry was given.
    fn section_stiffness(
        &mut self,
        v: &View,
        block: &Block,
        p: &Props,
    ) -> Option<([[f64; 6]; 6], bool)> {
        const DIAG: [(&str, Quantity); 6] = [
            ("EA", units::AXIAL_STIFFNESS),
            ("GA2", units::SHEAR_STIFFNESS),
            ("GA3", units::SHEAR_STIFFNESS),
            ("GJ", units::TORSIONAL_RIGIDITY),
            ("EI2", BENDING),
            ("EI3", BENDING),
        ];
        let mut k = [[0.0; 6]; 6];
        let mut ok = true;
        if let Some(sp) = p.get("stiffness") {
            const OFFSETS: [&str; 4] = [
                "tension_offset2",
                "tension_offset3",
                "shear_offset2",
                "shear_offset3",
            ];
            let diagonal = DIAG.iter().map(|(n, _)| *n).chain(OFFSETS);
            if let Some(name) = diagonal.into_iter().find(|n| p.contains_key(n)) {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0224, "a section gives either `stiffness` (6x6) or the diagonal stiffnesses and centres, not both")
                        .at(p.get(name).map(|q| q.name.span).unwrap_or(sp.name.span), "engineering property")
                        .at(sp.name.span, "full matrix")
                        .hint("keep one of them: a 6x6 `stiffness` already holds the couplings that offset centres give"),
                );
                return None;
            }
            k = self.matrix6(v, sp, &STIFFNESS)?;
        } else {
            for (i, (key, dim)) in DIAG.iter().enumerate() {
                let example = if i < 3 { "8.53e7 N" } else { "1.28e4 N*m^2" };
                match self
                    .required(v.scope, p, key, block.span, "a section", example)
                    .and_then(|e| self.scalar(v.scope, e, *dim, &format!("`{key}`")))
                {
                    Some(x) => k[i][i] = x,
                    None => ok = false,
                }
            }
            let mut offset = |key: &str| match self.expr(v.scope, p.get(key)) {
                Some(e) => self.scalar(v.scope, e, Dim::LENGTH, &format!("`{key}`")),
                None => Some(0.0),
            };
            let (t2, t3, s2, s3) = (
                offset("tension_offset2"),
                offset("tension_offset3"),
                offset("shear_offset2"),
                offset("shear_offset3"),
            );
            match (t2, t3, s2, s3) {
                (Some(t2), Some(t3), Some(s2), Some(s3)) => offsets(&mut k, [t2, t3], [s2, s3]),
                _ => ok = false,
            }
        }
        Some((k, ok))
    }

    /// The mass per length, its offset (axes 2, 3) and the inertias about the centre of mass
    /// (polar, 2, 3, products): written as properties, or as the 6x6 mass matrix.
    #[allow(clippy::type_complexity)]
    fn section_mass(
        &mut self,
        v: &View,
        block: &Block,
        p: &Props,
    ) -> Option<(f64, [f64; 2], [[f64; 3]; 3])> {
        if let Some(mp) = p.get("mass_matrix") {
            const PARTS: [&str; 6] = [
                "mass_per_length",
                "mass_offset2",
                "mass_offset3",
                "i2",
                "i3",
                "polar",
            ];
            if let Some(name) = PARTS.iter().find(|n| p.contains_key(*n)) {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0224, "a section gives either `mass_matrix` (6x6) or the mass per length, its offsets and inertias, not both")
                        .at(p.get(name).map(|q| q.name.span).unwrap_or(mp.name.span), "engineering property")
                        .at(mp.name.span, "full matrix")
                        .hint("keep one of them: the 6x6 mass matrix holds the mass, its offset and the inertias"),
                );
                return None;
            }
            let m = self.matrix6(v, mp, &MASS)?;
            return self.mass_parts(v, mp, &m);
        }
        let mass = self
            .required(
                v.scope,
                p,
                "mass_per_length",
                block.span,
                "a section",
                "3.29 kg/m",
            )
            .and_then(|e| self.scalar(v.scope, e, Dim::new(1, -1, 0), "`mass_per_length`"));
        let get = |this: &mut Self, key: &str, dim: Dim| match this.expr(v.scope, p.get(key)) {
            Some(e) => this.scalar(v.scope, e, dim, &format!("`{key}`")),
            None => Some(0.0),
        };
        let o2 = get(self, "mass_offset2", Dim::LENGTH);
        let o3 = get(self, "mass_offset3", Dim::LENGTH);
        let i2 = get(self, "i2", Dim::new(1, 1, 0));
        let i3 = get(self, "i3", Dim::new(1, 1, 0));
        let polar = match self.expr(v.scope, p.get("polar")) {
            Some(e) => self.scalar(v.scope, e, Dim::new(1, 1, 0), "`polar`"),
            None => match (i2, i3) {
                (Some(a), Some(b)) => Some(a + b),
                _ => None,
            },
        };
        let (mass, o2, o3, i2, i3, polar) = (mass?, o2?, o3?, i2?, i3?, polar?);
        let inertia = [[polar, 0.0, 0.0], [0.0, i2, 0.0], [0.0, 0.0, i3]];
        Some((mass, [o2, o3], inertia))
    }

    /// The mass, the offset and the inertias about the centre of mass of a 6x6 mass matrix
    /// `[[m I, m eta~^T], [m eta~, rho]]` (section axes, about the reference line): the
    /// translational block a multiple of the identity, the coupling block `m eta~` with the
    /// centre of mass in the section plane (E0213 otherwise; positive definiteness is checked
    /// with the section).
    fn mass_parts(
        &mut self,
        v: &View,
        mp: &Prop,
        m: &[[f64; 6]; 6],
    ) -> Option<(f64, [f64; 2], [[f64; 3]; 3])> {
        let mass = m[0][0];
        let scale = m
            .iter()
            .enumerate()
            .map(|(i, r)| r[i].abs())
            .fold(0.0, f64::max);
        let small = |x: f64| x.abs() <= 1e-9 * scale;
        let translational =
            (0..3).all(|i| (0..3).all(|j| small(m[i][j] - if i == j { mass } else { 0.0 })));
        // The lower-left block is m eta~: its (1, 0) is m eta_3, (0, 2) m eta_2, (2, 1) m eta_1.
        let c = |i: usize, j: usize| m[3 + i][j];
        let eta = [c(2, 1) / mass, c(0, 2) / mass, c(1, 0) / mass];
        let skew = (0..3).all(|i| small(c(i, i)))
            && small(c(0, 1) + c(1, 0))
            && small(c(0, 2) + c(2, 0))
            && small(c(1, 2) + c(2, 1));
        let why = if !translational {
            Some("its translational block (rows and columns 1-3) must be the mass per length times the identity")
        } else if !skew {
            Some("its coupling block (rows 4-6, columns 1-3) must be `m eta~`: skew, the mass times the centre of mass's offset")
        } else if mass > 0.0 && !small(mass * eta[0]) {
            Some("the centre of mass lies in the section's plane: its offset along axis 1 (entries (5, 3) and (6, 2)) must be 0")
        } else {
            None
        };
        if let Some(why) = why {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0213, format!("`mass_matrix` is not a section's mass matrix: {why}"))
                    .at(mp.span(), "here")
                    .hint("rows 1-3 hold `m I` (kg/m) and `-m eta~` (kg), rows 4-6 `m eta~` (kg) and the inertias per length about the reference line (kg*m), `eta = (0, e2, e3)` the centre of mass: row 1 is `(m, 0, 0, 0, m*e3, -m*e2)`"),
            );
            return None;
        }
        // Inertias about the centre of mass: rho - m (|eta|^2 I - eta eta^T).
        let e2 = eta[1] * eta[1] + eta[2] * eta[2];
        let inertia = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let parallel = if i == j { e2 } else { 0.0 } - eta[i] * eta[j];
                m[3 + i][3 + j] - mass * parallel
            })
        });
        Some((mass, [eta[1], eta[2]], inertia))
    }

    /// A positive mass, non-negative inertias and a symmetric positive definite stiffness.
    fn check_section(&mut self, v: &View, block: &Block, p: &Props, s: &Section) -> bool {
        let (name, mass, k) = (&s.name, s.mass_per_length, &s.stiffness);
        if mass <= 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0302,
                    format!("section `{name}` has a non-positive mass per length"),
                )
                .at(
                    p.get("mass_per_length")
                        .map(|q| q.span())
                        .unwrap_or(block.span),
                    format!("{mass} kg/m"),
                )
                .hint("a beam needs mass; a massless beam makes the iteration matrix singular"),
            );
            return false;
        }
        let j = nalgebra::Matrix3::from_fn(|i, k| s.inertia[i][k]);
        let sym =
            (0..3).all(|i| (0..3).all(|k| (j[(i, k)] - j[(k, i)]).abs() <= 1e-9 * j.trace().abs()));
        let least = j.symmetric_eigenvalues().min();
        if !sym || least < -1e-12 * j.trace().abs() {
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0311,
                    format!("section `{name}` has a negative mass moment of inertia"),
                )
                .at(block.span, "in this section")
                .hint("i2, i3 and polar are non-negative (kg*m); a mass matrix's inertias about the centre of mass must be symmetric and positive semidefinite"),
            );
            return false;
        }
        let m = nalgebra::Matrix6::from_fn(|i, j| k[i][j]);
        let sym = (0..6).all(|i| {
            (0..6).all(|j| (k[i][j] - k[j][i]).abs() <= 1e-9 * (k[i][i].abs() + k[j][j].abs()))
        });
        if !sym || m.cholesky().is_none() {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0311, format!("the stiffness of section `{name}` is not symmetric positive definite"))
                    .at(block.span, "in this section")
                    .hint("every stiffness must be positive (a beam stiff in some direction still needs a finite value), and couplings must leave the matrix positive definite"),
            );
            return false;
        }
        true
    }

    /// `stiffness = ((k11, ..., k16), ..., (k61, ..., k66))` (or a `mass_matrix`) with
    /// per-block units.
    fn matrix6(
        &mut self,
        v: &View,
        p: &crate::syntax::ast::Prop,
        kind: &Matrix6,
    ) -> Option<[[f64; 6]; 6]> {
        use crate::syntax::ast::ExprKind;
        let bad = |this: &mut Self, span: Span| {
            this.error(
                v.scope,
                Diagnostic::error(Code::E0209, format!("`{}` must be a 6x6 matrix", kind.name))
                    .at(span, "not six rows of six")
                    .hint(kind.shape),
            );
            None
        };
        let PropValue::Expr(e) = &p.value else {
            return bad(self, p.name.span);
        };
        let ExprKind::Vector {
            items: rows,
            unit: None,
        } = &e.kind
        else {
            return bad(self, e.span);
        };
        if rows.len() != 6 {
            return bad(self, e.span);
        }
        let mut k = [[0.0; 6]; 6];
        for (i, row) in rows.iter().enumerate() {
            let ExprKind::Vector { items, unit } = &row.kind else {
                return bad(self, row.span);
            };
            if items.len() != 6 {
                return bad(self, row.span);
            }
            for (j, item) in items.iter().enumerate() {
                let dim = Dim::new(1, kind.length + (i >= 3) as i8 + (j >= 3) as i8, kind.time);
                // A row may carry one unit after its parenthesis: apply it to every entry.
                let val = self.value(v.scope, item)?;
                let (x, d) = match (val, unit) {
                    (Value::Scalar { value, dim: d }, Some(u)) => {
                        let wrapped = crate::syntax::ast::Expr {
                            kind: ExprKind::Quantity {
                                value: 1.0,
                                unit: Some(u.clone()),
                            },
                            span: u.span,
                        };
                        let f = self.value(v.scope, &wrapped)?;
                        (value * scalar_of(&f), d.times(f.dim()))
                    }
                    (Value::Scalar { value, dim: d }, None) => (value, d),
                    (other, _) => {
                        self.error(
                            v.scope,
                            Diagnostic::error(
                                Code::E0209,
                                format!(
                                    "a `{}` entry must be a constant scalar, found {}",
                                    kind.name,
                                    other.kind_name()
                                ),
                            )
                            .at(item.span, "here")
                            .hint("write numbers with units"),
                        );
                        return None;
                    }
                };
                if x != 0.0 && d != dim {
                    self.error(
                        v.scope,
                        Diagnostic::error(
                            Code::E0202,
                            format!(
                                "`{}` entry ({}, {}) must be {}, found {}",
                                kind.name,
                                i + 1,
                                j + 1,
                                dim.describe(),
                                d.describe()
                            ),
                        )
                        .at(item.span, format!("this is {}", d.describe()))
                        .hint(kind.units),
                    );
                    return None;
                }
                k[i][j] = x;
            }
        }
        Some(k)
    }

    pub(super) fn section_ref(
        &mut self,
        v: &View,
        e: &crate::syntax::ast::Expr,
    ) -> Option<Section> {
        use crate::syntax::ast::ExprKind;
        let ExprKind::Path { path } = &e.kind else {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0222, "`section` names a section")
                    .at(e.span, "not a name")
                    .hint("write `section = NAME` or `section = { EA = ..., ... }`"),
            );
            return None;
        };
        let r = self
            .env
            .segs(v.scope, path)
            .and_then(|s| self.env.resolve(v.scope, &s, path.span));
        match r {
            Ok((Ref::Decl(d), rest)) if rest.is_empty() => match self.built[d] {
                Some(Built::Section(i)) => Some(self.sections[i].clone()),
                None if self.env.decls[d].item_kind() == Some("section") => None,
                _ => {
                    self.error(
                        v.scope,
                        Diagnostic::error(
                            Code::E0222,
                            format!("`{}` is not a section", self.env.decls[d].name),
                        )
                        .at(e.span, "not a section")
                        .hint("declare one with `section NAME { ... }`"),
                    );
                    None
                }
            },
            Ok(_) => {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0222, "`section` names a section")
                        .at(e.span, "not a section")
                        .hint("declare one with `section NAME { ... }`"),
                );
                None
            }
            Err(d) => {
                self.error(v.scope, d);
                None
            }
        }
    }
}

fn scalar_of(v: &Value) -> f64 {
    match v {
        Value::Scalar { value, .. } => *value,
        _ => 1.0,
    }
}

/// The stiffness about the reference line of a section whose axial stiffness acts at the
/// tension centre `t` and whose shear stiffnesses act at the shear centre `c` (offsets along
/// axes 2, 3; `k` holds the diagonal, bending and torsion about those centres). A fibre at
/// `(x2, x3)` stretches by `gamma1 + x3 kappa2 - x2 kappa3`, and the shear centre moves across
/// by `(-c3, c2) kappa1` under a twist, so the strains there are
/// `gamma1 + t3 kappa2 - t2 kappa3`, `gamma2 - c3 kappa1` and `gamma3 + c2 kappa1`.
fn offsets(k: &mut [[f64; 6]; 6], t: [f64; 2], c: [f64; 2]) {
    // Each stiffness with its strain as a combination of the reference line's.
    let (ea, ga2, ga3) = (k[0][0], k[1][1], k[2][2]);
    let rows: [(f64, [f64; 6]); 3] = [
        (ea, [1.0, 0.0, 0.0, 0.0, t[1], -t[0]]),
        (ga2, [0.0, 1.0, 0.0, -c[1], 0.0, 0.0]),
        (ga3, [0.0, 0.0, 1.0, c[0], 0.0, 0.0]),
    ];
    for (r, (stiffness, b)) in rows.iter().enumerate() {
        // Replace the diagonal entry by the full b^T stiffness b.
        k[r][r] = 0.0;
        for i in 0..6 {
            for j in 0..6 {
                k[i][j] += stiffness * b[i] * b[j];
            }
        }
    }
}
