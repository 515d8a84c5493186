//! Declarations: one parse tree item to one AST [`Item`], a function per kind of
//! declaration with a body of its own. Contract: reads the tree the grammar guarantees
//! (missing pairs are internal errors, never panics); must not resolve names.

use super::*;

impl Cx {
    pub(super) fn item(&self, p: Pair<Rule>) -> Parsed<Item> {
        let span = self.span(&p);
        let rule = p.as_rule();
        let mut it = p.into_inner();
        Ok(match rule {
            Rule::model_decl => {
                let name = self.ident(take(&mut it, "model name")?);
                let title = it.next().map(|s| s.into_inner().as_str().to_string());
                Item::Model { name, title, span }
            }
            Rule::use_decl => {
                let q = take(&mut it, "use target")?;
                let target = match q.as_rule() {
                    Rule::string => UseTarget::File(q.into_inner().as_str().to_string()),
                    _ => UseTarget::Module(q.into_inner().map(|i| self.ident(i)).collect()),
                };
                Item::Use { target, span }
            }
            Rule::param_decl | Rule::let_decl | Rule::function_decl => {
                let name = self.ident(take(&mut it, "name")?);
                let value = self.expr(take(&mut it, "value")?)?;
                match rule {
                    Rule::param_decl => Item::Param { name, value, span },
                    Rule::let_decl => Item::Let { name, value, span },
                    _ => Item::Function { name, value, span },
                }
            }
            Rule::gravity_decl => Item::Gravity {
                value: self.expr(take(&mut it, "gravity value")?)?,
                span,
            },
            Rule::joint_decl => return self.joint(it, span),
            Rule::output_decl => Item::Output {
                items: it.map(|q| self.output_item(q)).collect::<Parsed<_>>()?,
                span,
            },
            Rule::solve_decl => return self.solve(it, span),
            Rule::component_decl => return self.component(it, span),
            Rule::for_decl => {
                let var = self.ident(take(&mut it, "loop variable")?);
                let from = self.expr(take(&mut it, "range start")?)?;
                let inclusive = take(&mut it, "range")?.as_str() == "..=";
                let to = self.expr(take(&mut it, "range end")?)?;
                let items = self.items(take(&mut it, "loop body")?.into_inner())?;
                Item::For {
                    var,
                    from,
                    to,
                    inclusive,
                    items,
                    span,
                }
            }
            Rule::if_decl => return self.if_decl(it, span),
            Rule::export_decl => {
                let mut items = Vec::new();
                for q in it {
                    let mut jt = q.into_inner();
                    let name = self.ident(take(&mut jt, "export name")?);
                    let target = jt.next().map(|p| self.path(p)).transpose()?;
                    items.push(ExportItem { name, target });
                }
                Item::Export { items, span }
            }
            Rule::instance_decl => return self.instance(it, span),
            Rule::initial_decl => return self.initial(it, span),
            Rule::exact_decl => {
                // The `exact` keyword is its own pair.
                let mut it = it.filter(|q| q.as_rule() != Rule::kw_exact);
                let channel = self.path(take(&mut it, "exact channel")?)?;
                let value = self.expr(take(&mut it, "exact value")?)?;
                Item::Exact {
                    channel,
                    value,
                    span,
                }
            }
            Rule::entity_decl => return self.entity(it, span),
            _ => return Err(internal("a declaration").at(span, "here")),
        })
    }

    /// `joint NAME = KIND(a, b) { ... }`.
    fn joint(&self, mut it: Pairs<Rule>, span: Span) -> Parsed<Item> {
        let name = self.name(take(&mut it, "joint name")?)?;
        let kind = self.ident(take(&mut it, "joint kind")?);
        let markers = self.connection(take(&mut it, "joint markers")?)?;
        let block = match it.next() {
            Some(b) => self.block(b)?,
            None => Block {
                span: Span {
                    start: span.end,
                    ..span
                },
                ..Block::default()
            },
        };
        Ok(Item::Joint {
            name,
            kind,
            markers,
            block,
            span,
        })
    }

    /// `solve METHOD(args) { ... }`.
    fn solve(&self, mut it: Pairs<Rule>, span: Span) -> Parsed<Item> {
        let method = self.ident(take(&mut it, "solver name")?);
        let mut args = Vec::new();
        let mut block = Block {
            span: Span {
                start: span.end,
                ..span
            },
            ..Block::default()
        };
        for q in it {
            match q.as_rule() {
                Rule::solve_args => {
                    args = q
                        .into_inner()
                        .map(|p| self.prop(p))
                        .collect::<Parsed<_>>()?
                }
                _ => block = self.block(q)?,
            }
        }
        Ok(Item::Solve {
            method,
            args,
            block,
            span,
        })
    }

    /// `component NAME(params) { ... }`.
    fn component(&self, mut it: Pairs<Rule>, span: Span) -> Parsed<Item> {
        let name = self.ident(take(&mut it, "component name")?);
        let mut params = Vec::new();
        let mut items = Vec::new();
        for q in it {
            match q.as_rule() {
                Rule::comp_param => {
                    let pspan = self.span(&q);
                    let mut jt = q.into_inner();
                    let pname = self.ident(take(&mut jt, "parameter name")?);
                    let ty = self.ident(take(&mut jt, "parameter type")?);
                    let default = jt.next().map(|e| self.expr(e)).transpose()?;
                    params.push(CompParam {
                        name: pname,
                        ty,
                        default,
                        span: pspan,
                    });
                }
                _ => items = self.items(q.into_inner())?,
            }
        }
        Ok(Item::Component(std::rc::Rc::new(Component {
            name,
            params,
            items,
            span,
        })))
    }

    /// `if COND { ... } else { ... }`, `else if` chained.
    fn if_decl(&self, mut it: Pairs<Rule>, span: Span) -> Parsed<Item> {
        let cond = self.expr(take(&mut it, "condition")?)?;
        let then = self.items(take(&mut it, "branch")?.into_inner())?;
        let mut otherwise = Vec::new();
        for q in it {
            match q.as_rule() {
                Rule::kw_else => {}
                Rule::if_decl => otherwise.push(self.item(q)?),
                _ => otherwise = self.items(q.into_inner())?,
            }
        }
        Ok(Item::If {
            cond,
            then,
            otherwise,
            span,
        })
    }

    /// `NAME = component(args)`; a marker argument may carry an offset.
    fn instance(&self, mut it: Pairs<Rule>, span: Span) -> Parsed<Item> {
        let name = self.name(take(&mut it, "instance name")?)?;
        let component = self.ident(take(&mut it, "component name")?);
        let args = it
            .map(|q| {
                let mut jt = q.into_inner();
                let name = self.ident(take(&mut jt, "argument name")?);
                let v = take(&mut jt, "argument value")?;
                if v.as_rule() == Rule::marker {
                    let m = self.marker(v)?;
                    let value = Expr {
                        span: m.path.span,
                        kind: ExprKind::Path { path: m.path },
                    };
                    return Ok(Arg {
                        name,
                        value,
                        offset: m.offset,
                    });
                }
                let value = self.expr(v)?;
                Ok(Arg {
                    name,
                    value,
                    offset: None,
                })
            })
            .collect::<Parsed<_>>()?;
        Ok(Item::Instance {
            name,
            component,
            args,
            span,
        })
    }

    /// `initial spin of PATH = rate about AXIS through POINT`, `initial velocity of PATH = v`.
    fn initial(&self, mut it: Pairs<Rule>, span: Span) -> Parsed<Item> {
        let what = self.ident(take(&mut it, "initial motion kind")?);
        let mut target = None;
        let mut value = None;
        let mut about = None;
        let mut through = None;
        let mut last = Rule::initial_decl;
        for q in it {
            match q.as_rule() {
                Rule::kw_of | Rule::kw_about | Rule::kw_through => last = q.as_rule(),
                Rule::path => target = Some(self.path(q)?),
                _ => {
                    let e = self.expr(q)?;
                    match last {
                        Rule::kw_about => about = Some(e),
                        Rule::kw_through => through = Some(e),
                        _ => value = Some(e),
                    }
                }
            }
        }
        Ok(Item::Initial {
            what,
            target: target.ok_or_else(|| internal("initial target").at(span, "here"))?,
            value: value.ok_or_else(|| internal("initial value").at(span, "here"))?,
            about,
            through,
            span,
        })
    }

    /// `KIND NAME flags (a, b) on MARKER = value { ... }`.
    fn entity(&self, mut it: Pairs<Rule>, span: Span) -> Parsed<Item> {
        let kind = self.ident(take(&mut it, "declaration kind")?);
        let name = self.name(take(&mut it, "declaration name")?)?;
        let mut flags = Vec::new();
        let mut markers = Vec::new();
        let mut on = None;
        let mut value = None;
        let mut block = None;
        for q in it {
            match q.as_rule() {
                Rule::flag => flags.push(self.ident(q)),
                Rule::connection => markers = self.connection(q)?,
                Rule::on_clause => {
                    let m = q
                        .into_inner()
                        .find(|r| r.as_rule() == Rule::marker)
                        .ok_or_else(|| internal("marker").at(span, "here"))?;
                    on = Some(self.marker(m)?)
                }
                Rule::block => block = Some(self.block(q)?),
                _ => value = Some(self.expr(q)?),
            }
        }
        Ok(Item::Entity {
            kind,
            name,
            flags,
            markers,
            on,
            value,
            block,
            span,
        })
    }
}
