//! Stations along a beam: the twist (an angle, or `((s, angle), ...)`) and the sections
//! (`((s, NAME), ...)`), linear between them and held beyond the ends; checked to lie within
//! the beam in increasing arc length. Contract: reads and checks the tables; must not build
//! beams.

use super::{Builder, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::{self, Dim};
use crate::model::*;

impl Builder<'_> {
    /// `twist`: an angle, or stations `((s, angle), ...)` with `s` the arc length from `from`.
    pub(super) fn twist(
        &mut self,
        scope: usize,
        e: &crate::syntax::ast::Expr,
    ) -> Option<Vec<(f64, f64)>> {
        use crate::syntax::ast::ExprKind;
        let rows = match &e.kind {
            ExprKind::Vector { items, unit: None }
                if items
                    .iter()
                    .all(|r| matches!(&r.kind, ExprKind::Vector { .. })) =>
            {
                items
            }
            _ => {
                let x = self.scalar(scope, e, units::ANGLE, "`twist`");
                if x.is_some() {
                    self.angle_unit(scope, Some(e), x, "`twist`");
                }
                return x.map(|a| vec![(0.0, a)]);
            }
        };
        let mut out = Vec::with_capacity(rows.len());
        for row in rows {
            let ExprKind::Vector { items, unit: None } = &row.kind else {
                continue;
            };
            if items.len() != 2 {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0209, "a twist station is an arc length and an angle")
                        .at(row.span, format!("{} entries", items.len()))
                        .hint("write `twist = ((0 m, 0 deg), (2.5 m, -8 deg))`: each station `(s, angle)`, s from the beam's `from`, each entry with its unit"),
                );
                return None;
            }
            let s = self.scalar(
                scope,
                &items[0],
                Dim::LENGTH,
                "a twist station's arc length",
            );
            let a = self.scalar(scope, &items[1], units::ANGLE, "a twist station's angle");
            if a.is_some() {
                self.angle_unit(scope, Some(&items[1]), a, "a twist station's angle");
            }
            out.push((s?, a?));
        }
        Some(out)
    }

    /// `section = ((s, NAME), ...)`: sections at stations, each a declared section.
    pub(super) fn section_stations(
        &mut self,
        v: &View,
        e: &crate::syntax::ast::Expr,
    ) -> Option<Vec<(f64, Section)>> {
        let mut out = Vec::new();
        for items in stations(e)? {
            if items.len() != 2 {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0209, "a section station is an arc length and a section")
                        .at(e.span, format!("a station with {} entries", items.len()))
                        .hint("write `section = ((0 m, root), (2.5 m, tip))`: each station `(s, NAME)`, s from the beam's `from`, NAME a declared section"),
                );
                return None;
            }
            let s = self.scalar(
                v.scope,
                &items[0],
                Dim::LENGTH,
                "a section station's arc length",
            );
            let section = self.section_ref(v, &items[1]);
            out.push((s?, section?));
        }
        Some(out)
    }

    /// Stations (of the twist or the section, `what`) within the beam (`0 <= s <= length`), in
    /// increasing arc length; `refuse` says why the beam takes none.
    pub(super) fn check_stations(
        &mut self,
        v: &View,
        what: &str,
        (at, span): (&[f64], Span),
        length: f64,
        refuse: Option<&str>,
    ) -> Option<()> {
        let inside = at
            .iter()
            .all(|&s| (-1e-12 * length..=length * (1.0 + 1e-12)).contains(&s));
        let increasing = at.windows(2).all(|w| w[1] > w[0]);
        let problem = if at.is_empty() {
            Some("no station")
        } else if !inside {
            Some("a station outside the beam")
        } else if !increasing {
            Some("stations not in increasing arc length")
        } else {
            refuse
        };
        let Some(problem) = problem else {
            return Some(());
        };
        self.error(
            v.scope,
            Diagnostic::error(Code::E0213, format!("the {what} of beam `{}` has {problem}", v.name))
                .at(span, problem)
                .hint(format!("give stations `(s, {what})` with s increasing from 0 to the beam's length ({length} m); a `rigid` beam takes one {what}, and `spin_stretch` one section")),
        );
        None
    }
}

/// The twist at arc length `s`: linear between the stations, held beyond the ends.
pub(super) fn twist_at(stations: &[(f64, f64)], s: f64) -> f64 {
    match stations {
        [] => 0.0,
        [(s0, a0), ..] if s <= *s0 => *a0,
        [.., (sl, al)] if s >= *sl => *al,
        _ => stations.windows(2).find(|w| s <= w[1].0).map_or(0.0, |w| {
            let f = (s - w[0].0) / (w[1].0 - w[0].0);
            w[0].1 + f * (w[1].1 - w[0].1)
        }),
    }
}

/// The rows of a table of stations, `((a, b), (c, d), ...)`: a vector of vectors (no unit
/// after the outer parenthesis, none after the rows); `None` if `e` is not one.
pub(super) fn stations(e: &crate::syntax::ast::Expr) -> Option<Vec<Vec<crate::syntax::ast::Expr>>> {
    use crate::syntax::ast::ExprKind;
    let ExprKind::Vector { items, unit: None } = &e.kind else {
        return None;
    };
    items
        .iter()
        .map(|r| match &r.kind {
            ExprKind::Vector { items, unit: None } => Some(items.clone()),
            _ => None,
        })
        .collect()
}
