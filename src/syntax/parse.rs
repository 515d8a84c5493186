//! The pest parser and the conversion of its pairs into the typed AST.

use super::ast::*;
use super::names::rule_name;
use crate::diagnostics::{Code, Diagnostic};
use crate::source::{SourceId, Span};
use pest::iterators::{Pair, Pairs};
use pest::pratt_parser::{Assoc, Op, PrattParser};
use pest::Parser;
use std::sync::OnceLock;

mod items;

#[derive(pest_derive::Parser)]
#[grammar = "../grammar/mbd.pest"]
struct MbdParser;

fn pratt() -> &'static PrattParser<Rule> {
    static PRATT: OnceLock<PrattParser<Rule>> = OnceLock::new();
    PRATT.get_or_init(|| {
        PrattParser::new()
            .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
            .op(Op::infix(Rule::mul, Assoc::Left) | Op::infix(Rule::div, Assoc::Left))
            .op(Op::prefix(Rule::neg))
            .op(Op::infix(Rule::pow, Assoc::Right))
    })
}

/// Deepest nesting of brackets the parser accepts (deeper input would exhaust the stack).
const MAX_NESTING: usize = 128;

/// Most operators one expression may hold, its brackets included: the expression tree is
/// at most this deep, which bounds every recursive pass over it (parse, evaluation, drop).
const MAX_OPERATORS: usize = 1000;

/// Rejects absurdly deep nesting before the recursive parser sees it.
fn check_nesting(text: &str, source: SourceId) -> Result<(), Diagnostic> {
    let mut depth = 0usize;
    let mut in_comment = false;
    for (i, c) in text.char_indices() {
        match c {
            '#' => in_comment = true,
            '\n' => in_comment = false,
            '(' | '{' | '[' if !in_comment => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Err(Diagnostic::error(
                        Code::E0101,
                        format!("brackets nest more than {MAX_NESTING} deep"),
                    )
                    .at(Span::new(source, i, i + 1), "too deep")
                    .hint("simplify the expression, or split it with `let`"));
                }
            }
            ')' | '}' | ']' if !in_comment => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    Ok(())
}

/// Parses a whole model file.
pub fn parse_file(text: &str, source: SourceId) -> Result<File, Diagnostic> {
    check_nesting(text, source)?;
    let mut pairs =
        MbdParser::parse(Rule::file, text).map_err(|e| syntax_error(e, text, source))?;
    let file = pairs
        .next()
        .ok_or_else(|| Diagnostic::error(Code::E0101, "empty parse"))?;
    let cx = Cx { source };
    let span = cx.span(&file);
    let items = cx.items(file.into_inner())?;
    Ok(File { items, span })
}

/// Parses a standalone expression, such as the VALUE of `--set NAME=VALUE`.
pub fn parse_expr(text: &str, source: SourceId) -> Result<Expr, Diagnostic> {
    check_nesting(text, source)?;
    let mut pairs =
        MbdParser::parse(Rule::expr_only, text).map_err(|e| syntax_error(e, text, source))?;
    let cx = Cx { source };
    let top = pairs.next().and_then(|p| p.into_inner().next());
    match top {
        Some(e) => cx.expr(e),
        None => Err(Diagnostic::error(Code::E0101, "expected an expression")),
    }
}

/// Parses a `--set` argument `NAME=VALUE` held as its own source text.
pub fn parse_set_arg(text: &str, source: SourceId) -> Result<(Ident, Expr), Diagnostic> {
    check_nesting(text, source)?;
    let mut pairs =
        MbdParser::parse(Rule::set_arg, text).map_err(|e| syntax_error(e, text, source))?;
    let cx = Cx { source };
    let mut it = pairs
        .next()
        .map(|p| p.into_inner())
        .ok_or_else(|| Diagnostic::error(Code::E0101, "expected NAME=VALUE"))?;
    match (it.next(), it.next()) {
        (Some(name), Some(value)) => Ok((cx.ident(name), cx.expr(value)?)),
        _ => Err(Diagnostic::error(Code::E0101, "expected NAME=VALUE")),
    }
}

/// Checks that `text` matches `rule` completely (used by the grammar tests).
pub fn parse_rule(rule: Rule, text: &str) -> bool {
    match MbdParser::parse(rule, text) {
        Ok(mut pairs) => pairs
            .next()
            .map(|p| p.as_span().end() == text.len())
            .unwrap_or(false),
        Err(_) => false,
    }
}

/// The end of the token that starts at `start`: a word (name or number), or one other
/// character; `start` itself at whitespace or the end of the text, where there is nothing to
/// point at.
fn token_end(text: &str, start: usize) -> usize {
    let rest = text.get(start..).unwrap_or("");
    let word = |c: char| c.is_alphanumeric() || c == '_' || c == '.';
    match rest.chars().next() {
        None => start,
        Some(c) if c.is_whitespace() => start,
        Some(c) if word(c) => start + rest.find(|c: char| !word(c)).unwrap_or(rest.len()),
        Some(c) => start + c.len_utf8(),
    }
}

fn syntax_error(e: pest::error::Error<Rule>, text: &str, source: SourceId) -> Diagnostic {
    use pest::error::{ErrorVariant, InputLocation};
    let (start, end) = match e.location {
        InputLocation::Pos(p) => (p, token_end(text, p)),
        InputLocation::Span((a, b)) => (a, b),
    };
    let expected = match &e.variant {
        ErrorVariant::ParsingError { positives, .. } => {
            let mut names: Vec<&str> = positives
                .iter()
                .filter(|r| !matches!(r, Rule::WHITESPACE | Rule::COMMENT | Rule::inline_ws))
                .map(|r| rule_name(*r))
                .collect();
            names.sort();
            names.dedup();
            names
        }
        ErrorVariant::CustomError { .. } => Vec::new(),
    };
    let at_item = matches!(&e.variant, ErrorVariant::ParsingError { positives, .. } if positives.contains(&Rule::model_decl));
    let expected = if at_item {
        vec!["a declaration"]
    } else {
        expected
    };
    let message = if expected.is_empty() {
        "unexpected text".to_string()
    } else {
        format!("expected {}", join_or(&expected))
    };
    Diagnostic::error(Code::E0101, format!("syntax error: {message}"))
        .at(Span::new(source, start, end.max(start)), "here")
        .hint(syntax_hint(&expected))
}

fn syntax_hint(expected: &[&str]) -> String {
    if expected.contains(&"a declaration") || expected.iter().any(|e| e.starts_with("`model")) {
        "a file is a list of declarations: model, use, param, let, function, gravity, bodies (`rigid NAME { ... }`), joints, components, `for` loops, output, solve"
            .to_string()
    } else if expected.contains(&"an expression") || expected.contains(&"a value") {
        "write a value here: a number with an optional unit (`0.5 m`), a param name, a vector `(x, y, z)` or a call".to_string()
    } else {
        "check the declaration against the examples of docs/language.md, the language reference"
            .to_string()
    }
}

fn join_or(items: &[&str]) -> String {
    match items.len() {
        0 => String::new(),
        1 => items[0].to_string(),
        n => format!("{} or {}", items[..n - 1].join(", "), items[n - 1]),
    }
}

struct Cx {
    source: SourceId,
}

type Parsed<T> = Result<T, Diagnostic>;

/// The pair the grammar guarantees at this point; an internal error (never a panic) if the
/// tree and the code ever disagree.
fn take<'i>(it: &mut impl Iterator<Item = Pair<'i, Rule>>, what: &str) -> Parsed<Pair<'i, Rule>> {
    it.next().ok_or_else(|| internal(what))
}

fn internal(what: &str) -> Diagnostic {
    Diagnostic::error(
        Code::E0101,
        format!("internal parser error: missing {what}"),
    )
    .hint("this is a bug in mbd's parser; please report it with the model file")
}

impl Cx {
    /// The pair's span without the whitespace pest's implicit separators leave at its end, so
    /// a label under a declaration stays on its lines.
    fn span(&self, p: &Pair<Rule>) -> Span {
        let s = p.as_span();
        let text = p.as_str();
        Span::new(self.source, s.start(), s.start() + text.trim_end().len())
    }

    fn ident(&self, p: Pair<Rule>) -> Ident {
        Ident {
            name: p.as_str().to_string(),
            span: self.span(&p),
        }
    }

    fn items(&self, pairs: Pairs<Rule>) -> Parsed<Vec<Item>> {
        pairs
            .filter(|p| p.as_rule() != Rule::EOI)
            .map(|p| self.item(p))
            .collect()
    }

    fn name(&self, p: Pair<Rule>) -> Parsed<Name> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let ident = self.ident(take(&mut it, "name")?);
        let index = match it.next() {
            Some(i) => Some(self.expr(take(&mut i.into_inner(), "index")?)?),
            None => None,
        };
        Ok(Name { ident, index, span })
    }

    fn connection(&self, p: Pair<Rule>) -> Parsed<Vec<MarkerRef>> {
        p.into_inner().map(|m| self.marker(m)).collect()
    }

    fn block(&self, p: Pair<Rule>) -> Parsed<Block> {
        let span = self.span(&p);
        let mut block = Block {
            span,
            ..Block::default()
        };
        for q in p.into_inner() {
            match q.as_rule() {
                Rule::marker_item => {
                    let mspan = self.span(&q);
                    let mut name = None;
                    let mut at = None;
                    let mut inner = None;
                    for r in q.into_inner() {
                        match r.as_rule() {
                            Rule::kw_marker => {}
                            Rule::name => name = Some(self.name(r)?),
                            Rule::block => inner = Some(self.block(r)?),
                            _ => at = Some(self.expr(r)?),
                        }
                    }
                    block.markers.push(MarkerItem {
                        name: name.ok_or_else(|| internal("marker name").at(mspan, "here"))?,
                        at,
                        block: inner,
                        span: mspan,
                    });
                }
                _ => block.props.push(self.prop(q)?),
            }
        }
        Ok(block)
    }

    fn prop(&self, p: Pair<Rule>) -> Parsed<Prop> {
        let mut it = p.into_inner();
        let name = self.ident(take(&mut it, "property name")?);
        let v = take(&mut it, "property value")?;
        let value = match v.as_rule() {
            Rule::block => PropValue::Block(self.block(v)?),
            _ => PropValue::Expr(self.expr(v)?),
        };
        Ok(Prop { name, value })
    }

    fn path(&self, p: Pair<Rule>) -> Parsed<Path> {
        let span = self.span(&p);
        let mut segments = Vec::new();
        for s in p.into_inner() {
            let sspan = self.span(&s);
            let mut it = s.into_inner();
            let name = self.ident(take(&mut it, "path segment")?);
            let mut index = None;
            let mut arg = None;
            if let Some(q) = it.next() {
                let is_index = q.as_rule() == Rule::index;
                let e = Box::new(self.expr(take(&mut q.into_inner(), "expression")?)?);
                if is_index {
                    index = Some(e);
                } else {
                    arg = Some(e);
                }
            }
            segments.push(Segment {
                name,
                index,
                arg,
                span: sspan,
            });
        }
        Ok(Path { segments, span })
    }

    fn marker(&self, p: Pair<Rule>) -> Parsed<MarkerRef> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let path = self.path(take(&mut it, "marker path")?)?;
        let offset = it.next().map(|e| self.expr(e)).transpose()?;
        Ok(MarkerRef { path, offset, span })
    }

    fn output_item(&self, p: Pair<Rule>) -> Parsed<OutputItem> {
        let span = self.span(&p);
        let mut name = None;
        let mut target = None;
        for q in p.into_inner() {
            match q.as_rule() {
                Rule::name => name = Some(self.name(q)?),
                Rule::output_call => target = Some(OutputTarget::Call(self.output_call(q)?)),
                _ => target = Some(OutputTarget::Path(self.path(q)?)),
            }
        }
        let target = target.ok_or_else(|| internal("output path").at(span, "here"))?;
        Ok(OutputItem { name, target, span })
    }

    fn output_call(&self, p: Pair<Rule>) -> Parsed<OutputCall> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let function = self.ident(take(&mut it, "output function name")?);
        let mut args = Vec::new();
        for a in take(&mut it, "output function arguments")?.into_inner() {
            let aspan = self.span(&a);
            let mut name = None;
            let mut value = None;
            for q in a.into_inner() {
                match q.as_rule() {
                    Rule::word => name = Some(self.ident(q)),
                    _ => value = Some(self.path(q)?),
                }
            }
            args.push(OutputArg {
                name,
                value: value.ok_or_else(|| internal("argument").at(aspan, "here"))?,
                span: aspan,
            });
        }
        let components = it.map(|w| self.ident(w)).collect();
        Ok(OutputCall {
            function,
            args,
            components,
            span,
        })
    }

    fn expr(&self, p: Pair<Rule>) -> Parsed<Expr> {
        let operators = p
            .clone()
            .into_inner()
            .flatten()
            .filter(|q| {
                matches!(
                    q.as_rule(),
                    Rule::add | Rule::sub | Rule::mul | Rule::div | Rule::pow | Rule::neg
                )
            })
            .count();
        if operators > MAX_OPERATORS {
            return Err(Diagnostic::error(
                Code::E0101,
                format!("an expression of {operators} operators: more than {MAX_OPERATORS}"),
            )
            .at(self.span(&p), "this expression")
            .hint("split it into named parts with `let`, or generate it with a `for` loop"));
        }
        pratt()
            .map_primary(|q| self.primary(q))
            .map_prefix(|op, rhs| {
                let rhs = rhs?;
                let span = self.span(&op).to(rhs.span);
                Ok(Expr {
                    kind: ExprKind::Neg {
                        operand: Box::new(rhs),
                    },
                    span,
                })
            })
            .map_infix(|lhs, op, rhs| {
                let (lhs, rhs) = (lhs?, rhs?);
                let op = match op.as_rule() {
                    Rule::add => BinOp::Add,
                    Rule::sub => BinOp::Sub,
                    Rule::mul => BinOp::Mul,
                    Rule::div => BinOp::Div,
                    _ => BinOp::Pow,
                };
                let span = lhs.span.to(rhs.span);
                Ok(Expr {
                    kind: ExprKind::Binary {
                        op,
                        lhs: Box::new(lhs),
                        rhs: Box::new(rhs),
                    },
                    span,
                })
            })
            .parse(p.into_inner())
    }

    fn primary(&self, p: Pair<Rule>) -> Parsed<Expr> {
        let span = self.span(&p);
        let kind = match p.as_rule() {
            Rule::quantity => {
                let mut it = p.into_inner();
                let number = take(&mut it, "number")?;
                // The grammar admits only valid float syntax; overflow gives inf, caught in eval.
                let value = number.as_str().parse::<f64>().unwrap_or(f64::NAN);
                let unit = it.next().map(|u| self.unit(u)).transpose()?;
                ExprKind::Quantity { value, unit }
            }
            Rule::vector => {
                let mut it = p.into_inner();
                let body = take(&mut it, "vector body")?;
                let items = body
                    .into_inner()
                    .map(|e| self.expr(e))
                    .collect::<Parsed<_>>()?;
                let unit = it.next().map(|u| self.unit(u)).transpose()?;
                ExprKind::Vector { items, unit }
            }
            Rule::call => {
                let mut it = p.into_inner();
                let function = self.ident(take(&mut it, "function name")?);
                let args = it.map(|e| self.expr(e)).collect::<Parsed<_>>()?;
                ExprKind::Call { function, args }
            }
            Rule::path => ExprKind::Path {
                path: self.path(p)?,
            },
            Rule::piecewise => {
                let mut mode = None;
                let mut knots = Vec::new();
                for q in p.into_inner() {
                    match q.as_rule() {
                        Rule::ident => mode = Some(self.ident(q)),
                        _ => {
                            let mut it = q.into_inner();
                            let t = self.expr(take(&mut it, "knot time")?)?;
                            let v = self.expr(take(&mut it, "knot value")?)?;
                            knots.push((t, v));
                        }
                    }
                }
                ExprKind::Piecewise { mode, knots }
            }
            Rule::expr => self.expr(p)?.kind,
            _ => return Err(internal("a value").at(span, "here")),
        };
        Ok(Expr { kind, span })
    }

    fn unit(&self, p: Pair<Rule>) -> Parsed<UnitExpr> {
        let span = self.span(&p);
        let mut factors = Vec::new();
        let mut op = UnitOp::Mul;
        for q in p.into_inner() {
            match q.as_rule() {
                Rule::unit_op => {
                    op = if q.as_str() == "/" {
                        UnitOp::Div
                    } else {
                        UnitOp::Mul
                    }
                }
                _ => {
                    let mut it = q.into_inner();
                    let name = self.ident(take(&mut it, "unit name")?);
                    let exponent = it
                        .next()
                        .and_then(|e| e.as_str().parse::<i32>().ok())
                        .unwrap_or(1);
                    factors.push(UnitFactor { op, name, exponent });
                }
            }
        }
        Ok(UnitExpr { factors, span })
    }
}
