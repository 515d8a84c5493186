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

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Prop {
    pub name: Ident,
    pub value: Expr,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MarkerRef {
    pub path: Path,
    /// Offset of the marker from the body's reference point, `body @ (x, y, z)`.
    pub offset: Option<Expr>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Path {
    pub segments: Vec<Ident>,
    pub span: Span,
}

impl Path {
    pub fn text(&self) -> String {
        self.segments
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(".")
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputItem {
    pub name: Option<Ident>,
    pub path: Path,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "item", rename_all = "snake_case")]
pub enum Item {
    Model {
        name: Ident,
        title: Option<String>,
        span: Span,
    },
    Param {
        name: Ident,
        value: Expr,
        span: Span,
    },
    Gravity {
        value: Expr,
        span: Span,
    },
    Ground {
        name: Ident,
        span: Span,
    },
    PointMass {
        name: Ident,
        props: Vec<Prop>,
        span: Span,
    },
    Joint {
        name: Ident,
        kind: Ident,
        markers: Vec<MarkerRef>,
        props: Vec<Prop>,
        span: Span,
    },
    Output {
        items: Vec<OutputItem>,
        span: Span,
    },
    Solve {
        method: Ident,
        args: Vec<Prop>,
        props: Vec<Prop>,
        span: Span,
    },
}

impl Item {
    pub fn span(&self) -> Span {
        match self {
            Item::Model { span, .. }
            | Item::Param { span, .. }
            | Item::Gravity { span, .. }
            | Item::Ground { span, .. }
            | Item::PointMass { span, .. }
            | Item::Joint { span, .. }
            | Item::Output { span, .. }
            | Item::Solve { span, .. } => *span,
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
}
