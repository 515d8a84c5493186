//! The `solve` block, with command-line overrides applied.

use super::build::Builder;
use super::env::ScopeId;
use super::units::Dim;
use super::*;
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::syntax::ast::{Block, ExprKind, Item, Prop};

impl Builder<'_> {
    pub(super) fn solve(
        &mut self,
        item: Option<&Item>,
        o: &Overrides,
        top: ScopeId,
        file_span: Span,
        header: Span,
    ) -> Option<SolveSpec> {
        if item.is_none() && (o.until.is_none() || (o.dt.is_none() && o.steps.is_none())) {
            self.error(
                top,
                Diagnostic::error(Code::E0229, "the model has no `solve` block")
                    .at(header, "this model has no `solve` block")
                    .hint("add one at the top level of the model file, e.g. `solve hht { dt = 1 ms, until = 1 s }`: the method, the time step and the end time"),
            );
            return None;
        }
        let (method, props, span) = match item {
            Some(Item::Solve {
                method,
                args,
                block,
                span,
            }) => (
                Some(method),
                args.iter()
                    .chain(block.props.iter())
                    .cloned()
                    .collect::<Vec<Prop>>(),
                *span,
            ),
            _ => (
                None,
                Vec::new(),
                Span {
                    end: file_span.start,
                    ..file_span
                },
            ),
        };
        let mut integrator = Integrator::Hht;
        if let Some(m) = method {
            integrator = match m.name.as_str() {
                "hht" => Integrator::Hht,
                "generalized_alpha" => Integrator::GeneralizedAlpha,
                "fet" => Integrator::Fet,
                "static" => Integrator::Static,
                other => {
                    let hint = match did_you_mean(other, ["hht", "generalized_alpha", "fet", "static"]) {
                        Some(s) => format!("did you mean `{s}`? Solvers: hht, generalized_alpha, fet, static"),
                        None => "solvers: hht (HHT-alpha), generalized_alpha, fet (time finite elements), static (load steps)".to_string(),
                    };
                    self.error(
                        top,
                        Diagnostic::error(Code::E0211, format!("unknown solver `{other}`"))
                            .at(m.span, "not a solver")
                            .hint(hint),
                    );
                    return None;
                }
            };
        }
        let block = Block {
            props,
            markers: Vec::new(),
            span,
        };
        let p = self.props(
            top,
            Some(&block),
            &[
                "alpha",
                "rho_inf",
                "rotations",
                "dt",
                "steps",
                "until",
                "every",
                "start",
                "tolerance",
                "max_iterations",
            ],
            "a solve block",
        );
        let mut alpha = match self.expr(top, p.get("alpha")) {
            Some(a) => self.scalar(top, a, Dim::NONE, "`alpha`")?,
            None => -0.1,
        };
        if let Some(crate::syntax::ast::PropValue::Expr(a)) = p.get("alpha").map(|p| &p.value) {
            if !(-1.0 / 3.0 - 1e-12..=0.0).contains(&alpha) {
                self.error(top, Diagnostic::error(Code::E0213, format!("HHT alpha = {alpha} is outside [-1/3, 0]")).at(a.span, "out of range").hint("alpha = -0.1 is the usual choice; 0 adds no numerical dissipation, -1/3 the most"));
                return None;
            }
        }
        let mut rho_inf = match self.expr(top, p.get("rho_inf")) {
            Some(r) => self.scalar(top, r, Dim::NONE, "`rho_inf`")?,
            None => 0.8,
        };
        if let Some(crate::syntax::ast::PropValue::Expr(r)) = p.get("rho_inf").map(|p| &p.value) {
            if !(0.0..=1.0).contains(&rho_inf) {
                self.error(top, Diagnostic::error(Code::E0213, format!("rho_inf = {rho_inf} is outside [0, 1]")).at(r.span, "out of range").hint("rho_inf is the spectral radius at infinite frequency: 1 adds no dissipation, 0 the most; 0.8 is usual"));
                return None;
            }
        }
        let mut rotations = match self.expr(top, p.get("rotations")) {
            Some(s) => match &s.kind {
                ExprKind::Path { path } if path.text() == "incremental" => Rotations::Incremental,
                ExprKind::Path { path } if path.text() == "conformal" => Rotations::Conformal,
                _ => {
                    self.error(top, Diagnostic::error(Code::E0211, "unknown rotation treatment").at(s.span, "not a rotation treatment").hint("`rotations = incremental` (default: stored rotations, incremental parameters) or `rotations = conformal` (the paper's total conformal rotation vector, rescaled past pi)"));
                    return None;
                }
            },
            None => Rotations::Incremental,
        };
        let mut dt = match self.expr(top, p.get("dt")) {
            Some(d) => Some((self.scalar(top, d, Dim::TIME, "`dt`")?, d.span)),
            None => None,
        };
        let mut steps = match self.expr(top, p.get("steps")) {
            Some(s) => Some(self.integer(top, s, "`steps`", 1)?),
            None => None,
        };
        let mut until = match self.expr(top, p.get("until")) {
            Some(u) => Some((self.scalar(top, u, Dim::TIME, "`until`")?, u.span)),
            None => None,
        };
        let mut every = match self.expr(top, p.get("every")) {
            Some(e) => self.integer(top, e, "`every`", 1)?,
            None => 1,
        };
        let mut start = match self.expr(top, p.get("start")) {
            Some(s) => match &s.kind {
                ExprKind::Path { path } if path.text() == "consistent" => Start::Consistent,
                ExprKind::Path { path } if path.text() == "zero_acceleration" => {
                    Start::ZeroAcceleration
                }
                _ => {
                    self.error(top, Diagnostic::error(Code::E0211, "unknown start").at(s.span, "not a start option").hint("`start = consistent` (default) or `start = zero_acceleration` (the paper's start)"));
                    return None;
                }
            },
            None => Start::Consistent,
        };
        let tolerance = match self.expr(top, p.get("tolerance")) {
            Some(t) => self.scalar(top, t, Dim::NONE, "`tolerance`")?,
            None => 1e-10,
        };
        let max_iterations = match self.expr(top, p.get("max_iterations")) {
            Some(m) => self.integer(top, m, "`max_iterations`", 1)?,
            None => 25,
        };
        for (name, value, s) in [("dt", dt, p.get("dt")), ("until", until, p.get("until"))] {
            if let (Some((v, vs)), Some(_)) = (value, s) {
                if v <= 0.0 {
                    self.error(
                        top,
                        Diagnostic::error(Code::E0213, format!("`{name}` must be positive"))
                            .at(vs, "not positive")
                            .hint("times are positive durations, e.g. `dt = 0.005 s`"),
                    );
                    return None;
                }
            }
        }
        if !(tolerance > 0.0 && tolerance < 1e-2) {
            self.error(
                top,
                Diagnostic::error(Code::E0213, "`tolerance` must lie in (0, 0.01)")
                    .at(
                        p.get("tolerance").map(|t| t.span()).unwrap_or(span),
                        "out of range",
                    )
                    .hint("the default 1e-10 is right for most models"),
            );
            return None;
        }
        // Command-line flags override the block.
        integrator = o.integrator.unwrap_or(integrator);
        alpha = o.alpha.unwrap_or(alpha);
        rho_inf = o.rho_inf.unwrap_or(rho_inf);
        rotations = o.rotations.unwrap_or(rotations);
        if let Some(d) = o.dt {
            dt = Some((d, span));
            steps = None;
        }
        if let Some(n) = o.steps {
            steps = Some(n);
            dt = None;
        }
        if let Some(u) = o.until {
            until = Some((u, span));
        }
        every = o.every.unwrap_or(every);
        start = o.start.unwrap_or(start);
        let Some((until, _)) = until else {
            self.missing(top, span, "until", "the solve block", "1 s");
            return None;
        };
        let (dt, steps) = match (dt, steps) {
            (_, Some(n)) => (until / n as f64, n),
            (Some((d, _)), None) => {
                // The last step is shortened by at most round-off: dt is rounded to fit `until`.
                let n = (until / d - 1e-9).ceil().max(1.0) as usize;
                (until / n as f64, n)
            }
            (None, None) => {
                self.missing(top, span, "dt", "the solve block", "0.005 s");
                return None;
            }
        };
        Some(SolveSpec {
            integrator,
            alpha,
            rho_inf,
            rotations,
            dt,
            steps,
            until,
            every,
            start,
            tolerance,
            max_iterations,
            span,
        })
    }
}
