//! The typed syntax tree. Every node carries the span of the text it came from.

use crate::source::Span;
use serde::Serialize;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct File {
    pub items: Vec<Item>,
    pub span: Span,
}

/// A declared name, optionally indexed: `blade[i]`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Name {
    pub ident: Ident,
    pub index: Option<Expr>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PropValue {
    Expr(Expr),
    Block(Block),
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Prop {
    pub name: Ident,
    pub value: PropValue,
}

impl Prop {
    pub fn span(&self) -> Span {
        match &self.value {
            PropValue::Expr(e) => self.name.span.to(e.span),
            PropValue::Block(b) => self.name.span.to(b.span),
        }
    }
}

/// `marker NAME = position { axes = ... }` inside a body block.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MarkerItem {
    pub name: Name,
    pub at: Option<Expr>,
    pub block: Option<Block>,
    pub span: Span,
}

/// `{ name = value, marker NAME = ..., ... }`
#[derive(Clone, Debug, PartialEq, Serialize, Default)]
pub struct Block {
    pub props: Vec<Prop>,
    pub markers: Vec<MarkerItem>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MarkerRef {
    pub path: Path,
    /// Offset of the marker from the body's reference point, `body @ (x, y, z)`.
    pub offset: Option<Expr>,
    pub span: Span,
}

/// One segment of a reference path: `blade[2]`, `root`, `at(1.5 m)`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Segment {
    pub name: Ident,
    pub index: Option<Box<Expr>>,
    pub arg: Option<Box<Expr>>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Path {
    pub segments: Vec<Segment>,
    pub span: Span,
}

impl Path {
    /// The path as written, with index and argument expressions shown as `[..]` and `(..)`.
    pub fn text(&self) -> String {
        self.segments
            .iter()
            .map(|s| {
                let mut t = s.name.name.clone();
                if s.index.is_some() {
                    t.push_str("[..]");
                }
                if s.arg.is_some() {
                    t.push_str("(..)");
                }
                t
            })
            .collect::<Vec<_>>()
            .join(".")
    }

    /// The single plain name this path is, if it is one (`bob`, not `bob.position`).
    pub fn single(&self) -> Option<&Ident> {
        match self.segments.as_slice() {
            [s] if s.index.is_none() && s.arg.is_none() => Some(&s.name),
            _ => None,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputItem {
    pub name: Option<Name>,
    pub target: OutputTarget,
    pub span: Span,
}

/// What an output item measures: a path to a quantity, or an output function.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum OutputTarget {
    /// `bob.position.x`
    Path(Path),
    /// `center_of_mass(rotor).x`
    Call(OutputCall),
}

/// `FUNCTION(arg, name = arg, ...).component...`: a quantity derived from several entities.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputCall {
    pub function: Ident,
    pub args: Vec<OutputArg>,
    /// The words after the closing parenthesis: `.velocity.x`.
    pub components: Vec<Ident>,
    pub span: Span,
}

/// One argument of an output function: a reference, positional or named.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputArg {
    pub name: Option<Ident>,
    pub value: Path,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompParam {
    pub name: Ident,
    pub ty: Ident,
    pub default: Option<Expr>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Component {
    pub name: Ident,
    pub params: Vec<CompParam>,
    pub items: Vec<Item>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Arg {
    pub name: Ident,
    /// The value; for `base = earth @ (0, 0, 1) m`, the path `earth`.
    pub value: Expr,
    /// The offset of a marker argument, `@ (0, 0, 1) m`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<Expr>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ExportItem {
    pub name: Ident,
    pub target: Option<Path>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", content = "value", rename_all = "snake_case")]
pub enum UseTarget {
    /// `use stdlib::rotor::lag_hinged_rotor`
    Module(Vec<Ident>),
    /// `use "parts/tower.mbd"`
    File(String),
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "item", rename_all = "snake_case")]
pub enum Item {
    Model {
        name: Ident,
        title: Option<String>,
        span: Span,
    },
    Use {
        target: UseTarget,
        span: Span,
    },
    Param {
        name: Ident,
        value: Expr,
        span: Span,
    },
    Let {
        name: Ident,
        value: Expr,
        span: Span,
    },
    Function {
        name: Ident,
        value: Expr,
        span: Span,
    },
    Gravity {
        value: Expr,
        span: Span,
    },
    Joint {
        name: Name,
        kind: Ident,
        markers: Vec<MarkerRef>,
        block: Block,
        span: Span,
    },
    Output {
        items: Vec<OutputItem>,
        span: Span,
    },
    Solve {
        method: Ident,
        args: Vec<Prop>,
        block: Block,
        span: Span,
    },
    Component(std::rc::Rc<Component>),
    For {
        var: Ident,
        from: Expr,
        to: Expr,
        inclusive: bool,
        items: Vec<Item>,
        span: Span,
    },
    /// `if cond { then } else { otherwise }`: the branch is chosen while elaborating.
    If {
        cond: Expr,
        then: Vec<Item>,
        otherwise: Vec<Item>,
        span: Span,
    },
    Export {
        items: Vec<ExportItem>,
        span: Span,
    },
    Instance {
        name: Name,
        component: Ident,
        args: Vec<Arg>,
        span: Span,
    },
    Initial {
        what: Ident,
        target: Path,
        value: Expr,
        about: Option<Expr>,
        through: Option<Expr>,
        span: Span,
    },
    /// `exact CHANNEL = expression of t`: the closed-form solution of an output channel.
    Exact {
        channel: Path,
        value: Expr,
        span: Span,
    },
    /// `KIND NAME flags (markers) on MARKER = value { block }`
    Entity {
        kind: Ident,
        name: Name,
        flags: Vec<Ident>,
        markers: Vec<MarkerRef>,
        on: Option<MarkerRef>,
        value: Option<Expr>,
        block: Option<Block>,
        span: Span,
    },
}

impl Item {
    pub fn span(&self) -> Span {
        match self {
            Item::Component(c) => c.span,
            Item::Model { span, .. }
            | Item::Use { span, .. }
            | Item::Param { span, .. }
            | Item::Let { span, .. }
            | Item::Function { span, .. }
            | Item::Gravity { span, .. }
            | Item::Joint { span, .. }
            | Item::Output { span, .. }
            | Item::Solve { span, .. }
            | Item::For { span, .. }
            | Item::If { span, .. }
            | Item::Export { span, .. }
            | Item::Instance { span, .. }
            | Item::Initial { span, .. }
            | Item::Exact { span, .. }
            | Item::Entity { span, .. } => *span,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum UnitOp {
    Mul,
    Div,
}

/// One factor of a unit: `m^2` in `kg*m^2`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UnitFactor {
    pub op: UnitOp,
    pub name: Ident,
    pub exponent: i32,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UnitExpr {
    pub factors: Vec<UnitFactor>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "expr", rename_all = "snake_case")]
pub enum ExprKind {
    Quantity {
        value: f64,
        unit: Option<UnitExpr>,
    },
    Vector {
        items: Vec<Expr>,
        unit: Option<UnitExpr>,
    },
    Path {
        path: Path,
    },
    Call {
        function: Ident,
        args: Vec<Expr>,
    },
    Neg {
        operand: Box<Expr>,
    },
    Binary {
        op: BinOp,
        lhs: Box<Expr>,
        rhs: Box<Expr>,
    },
    /// `piecewise MODE { t0: v0, t1: v1, ... }`
    Piecewise {
        mode: Option<Ident>,
        knots: Vec<(Expr, Expr)>,
    },
}
