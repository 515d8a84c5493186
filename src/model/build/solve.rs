//! The `solve` block: what the file wrote, evaluated (units checked, SI values) and recorded
//! with its spans as a [`Written`]. The ranges, defaults and the command line's overrides are
//! the settings module's ([`Settings::resolve`], called here to report the file's mistakes with
//! the rest of the model's).

use super::Builder;
use crate::model::eval::units::Dim;
use crate::model::scope::env::ScopeId;
use crate::model::*;
use crate::settings::{Field, Kind, Request, Settings, Written};
use crate::syntax::ast::{Block, ExprKind, Item, Prop};

impl Builder<'_> {
    pub(super) fn solve(
        &mut self,
        item: Option<&Item>,
        cli: &Request,
        top: ScopeId,
        header: Span,
    ) -> Option<Written> {
        let mut written = match item {
            Some(Item::Solve { span, .. }) => Written {
                request: Request::default(),
                spans: Vec::new(),
                span: *span,
                present: true,
            },
            _ => Written {
                request: Request::default(),
                spans: Vec::new(),
                span: header,
                present: false,
            },
        };
        if let Some(Item::Solve {
            method,
            args,
            block,
            span,
        }) = item
        {
            if let Err(d) = written
                .request
                .choose(Field::Method, Some(&method.name), method.span)
            {
                self.error(top, d);
                return None;
            }
            let props: Vec<Prop> = args.iter().chain(block.props.iter()).cloned().collect();
            let block = Block {
                props,
                markers: Vec::new(),
                span: *span,
            };
            self.solve_props(&block, top, &mut written)?;
        }
        match Settings::resolve(&written, cli) {
            Ok(_) => Some(written),
            Err(ds) => {
                for d in ds {
                    self.error(top, d);
                }
                None
            }
        }
    }

    /// Evaluates the block's properties into `written` (the first that fails stops it).
    fn solve_props(&mut self, block: &Block, top: ScopeId, written: &mut Written) -> Option<()> {
        let keys = Field::IN_BLOCK.map(Field::key);
        let p = self.props(top, Some(block), &keys, "a solve block");
        for field in Field::IN_BLOCK {
            let Some(e) = self.expr(top, p.get(field.key())) else {
                continue;
            };
            let what = format!("`{}`", field.key());
            match field.kind() {
                Kind::Time => {
                    let v = self.scalar(top, e, Dim::TIME, &what)?;
                    written.request.set(field, v);
                }
                Kind::Number => {
                    let v = self.scalar(top, e, Dim::NONE, &what)?;
                    written.request.set(field, v);
                }
                Kind::Count => {
                    let n = self.integer(top, e, &what, 1)?;
                    written.request.set(field, n as f64);
                }
                Kind::Choice => {
                    let word = match &e.kind {
                        ExprKind::Path { path } => Some(path.text()),
                        _ => None,
                    };
                    if let Err(d) = written.request.choose(field, word.as_deref(), e.span) {
                        self.error(top, d);
                        return None;
                    }
                }
            }
            written.spans.push((field, e.span));
        }
        Some(())
    }
}
