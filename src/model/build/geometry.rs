//! Shapes for the 3-D view only: `cylinder NAME(a, b) { radius }`, `box NAME on M { size }`,
//! `sphere NAME on M { radius }`, each with an optional `color = (r, g, b)`.
//! Contract: builds `Geometry` from its declaration; adds no mass, unknowns or topology.

use super::{Builder, Built, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::Dim;
use crate::model::*;

impl Builder<'_> {
    pub(super) fn geometry(&mut self, v: &View) -> Option<Built> {
        let k = v.kind.name.as_str();
        let (example, markers, on) = match k {
            "cylinder" => ("cylinder NAME(a, b) { radius = 0.1 m }", 2, false),
            "box" => ("box NAME on MARKER { size = (2, 1, 1) m }", 0, true),
            _ => ("sphere NAME on MARKER { radius = 0.1 m }", 0, true),
        };
        if !self.shape(v, markers, on, false, &[], example) {
            return None;
        }
        let known: &[&'static str] = if k == "box" {
            &["size", "color"]
        } else {
            &["radius", "color"]
        };
        let p = self.props(v.scope, v.block.as_ref(), known, &format!("a {k}"));
        let refs: Vec<_> = match &v.on {
            Some(m) => vec![m.clone()],
            None => v.markers.clone(),
        };
        let markers: Vec<Option<Marker>> = refs.iter().map(|m| self.marker(v.scope, m)).collect();
        let of = format!("{k} `{}`", v.name);
        let shape = if k == "box" {
            match self.expr(v.scope, p.get("size")) {
                Some(e) => {
                    let size = self.vector(v.scope, e, Dim::LENGTH, "`size`")?;
                    self.positive(v, e.span, &of, &size)?;
                    GeometryShape::Box { size }
                }
                None => {
                    self.missing(v.scope, v.name_span, "size", &of, "(2, 1, 1) m");
                    return None;
                }
            }
        } else {
            let radius = match self.expr(v.scope, p.get("radius")) {
                Some(e) => {
                    let r = self.scalar(v.scope, e, Dim::LENGTH, "`radius`")?;
                    self.positive(v, e.span, &of, &[r])?;
                    r
                }
                None => {
                    self.missing(v.scope, v.name_span, "radius", &of, "0.1 m");
                    return None;
                }
            };
            if k == "cylinder" {
                GeometryShape::Cylinder { radius }
            } else {
                GeometryShape::Sphere { radius }
            }
        };
        let color = match self.expr(v.scope, p.get("color")) {
            Some(e) => {
                let c = self.vector(v.scope, e, Dim::NONE, "`color`")?;
                if c.iter().any(|x| !(0.0..=1.0).contains(x)) {
                    self.error(
                        v.scope,
                        Diagnostic::error(Code::E0213, format!("{of} has a color out of range"))
                            .at(e.span, "each component must lie in 0..1")
                            .hint("write red, green and blue in 0..1, e.g. `color = (0.6, 0.6, 0.65)`"),
                    );
                    return None;
                }
                Some(c)
            }
            None => None,
        };
        let markers: Option<Vec<Marker>> = markers.into_iter().collect();
        self.geometry.push(Geometry {
            name: v.name.clone(),
            span: v.span,
            shape,
            markers: markers?,
            color,
        });
        Some(Built::Geometry)
    }

    /// E0213 unless every size is positive and finite.
    fn positive(&mut self, v: &View, at: Span, of: &str, sizes: &[f64]) -> Option<()> {
        if sizes.iter().all(|x| x.is_finite() && *x > 0.0) {
            return Some(());
        }
        self.error(
            v.scope,
            Diagnostic::error(Code::E0213, format!("{of} has a size that is not positive"))
                .at(at, "must be greater than zero")
                .hint("sizes of shapes are positive lengths"),
        );
        None
    }
}
