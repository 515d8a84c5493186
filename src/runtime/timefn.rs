//! Time functions: loads and prescribed motions as expression trees in `t`, values in SI.
//!
//! Built by the model stage from the language's `function`, `piecewise`, `ramp`, `step`,
//! `sine`, `constant` and arithmetic on `t`. Evaluated with their first two time derivatives
//! (forward-mode jets), because a prescribed angle needs its rate and acceleration too.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Unary {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sqrt,
    Abs,
    Exp,
    Ln,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Binary {
    Add,
    Sub,
    Mul,
    Div,
    Atan2,
    Min,
    Max,
}

/// What a piecewise-linear function does outside its first and last knot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outside {
    /// Constant: the first (last) knot's value.
    Hold,
    /// Continue the first (last) segment's slope.
    Extrapolate,
    /// Repeat with the period `t_last - t_first`.
    Periodic,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "f", rename_all = "snake_case")]
pub enum TimeFn {
    Const {
        value: f64,
    },
    /// The time `t` in seconds.
    Time,
    /// The arc length along a beam in metres (`span`), in a distributed load's value only:
    /// replaced by its value at each quadrature point before a run ([`TimeFn::at_arc`]).
    Arc,
    Unary {
        op: Unary,
        arg: Box<TimeFn>,
    },
    Binary {
        op: Binary,
        lhs: Box<TimeFn>,
        rhs: Box<TimeFn>,
    },
    /// `arg ^ exponent` with a constant exponent.
    Pow {
        arg: Box<TimeFn>,
        exponent: f64,
    },
    /// Linear between knots `(t_k, v_k)`, times non-decreasing (equal times make a jump; at
    /// the jump the later value holds). Evaluated at `arg` (plain `t` unless composed).
    Piecewise {
        knots: Vec<(f64, f64)>,
        outside: Outside,
        arg: Box<TimeFn>,
    },
}

/// A piecewise function's knots `(t_k, v_k)`.
pub type Knots = [(f64, f64)];

/// A value with its first and second time derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jet {
    pub v: f64,
    pub d: f64,
    pub dd: f64,
}

impl Jet {
    fn constant(v: f64) -> Jet {
        Jet { v, d: 0.0, dd: 0.0 }
    }

    /// Chain rule for `f(self)` given f, f', f'' at self.v.
    fn chain(self, f: f64, f1: f64, f2: f64) -> Jet {
        Jet {
            v: f,
            d: f1 * self.d,
            dd: f2 * self.d * self.d + f1 * self.dd,
        }
    }
}

impl TimeFn {
    pub fn constant(value: f64) -> TimeFn {
        TimeFn::Const { value }
    }

    pub fn binary(op: Binary, lhs: TimeFn, rhs: TimeFn) -> TimeFn {
        TimeFn::Binary {
            op,
            lhs: Box::new(lhs),
            rhs: Box::new(rhs),
        }
    }

    /// The constant value, if the function does not depend on `t`.
    pub fn as_constant(&self) -> Option<f64> {
        match self {
            TimeFn::Const { value } => Some(*value),
            _ => None,
        }
    }

    /// This function with `t` replaced by `inner` (composition `self(inner(t))`).
    pub fn compose(&self, inner: &TimeFn) -> TimeFn {
        self.substitute(&|f| matches!(f, TimeFn::Time).then(|| inner.clone()))
    }

    /// This function at arc length `s` (metres) along a beam: `span` replaced by `s`, and a
    /// function left without `t` evaluated once to its constant.
    pub fn at_arc(&self, s: f64) -> TimeFn {
        let f =
            self.substitute(&|f| matches!(f, TimeFn::Arc).then_some(TimeFn::Const { value: s }));
        if f.depends(&|f| matches!(f, TimeFn::Time)) {
            f
        } else {
            TimeFn::constant(f.eval(0.0))
        }
    }

    /// Whether the function depends on the span coordinate `span`.
    pub fn has_arc(&self) -> bool {
        self.depends(&|f| matches!(f, TimeFn::Arc))
    }

    /// The function's characteristic angular frequency over `[0, until]` (rad/s), for the
    /// sizing lint: `max |f''| / max |f'|` over 1,000 samples (`w` for `sin(w t)`, zero for a
    /// constant or a ramp), and `2 pi / dt` for the shortest interval `dt > 0` between the knots
    /// of a piecewise function inside the run (its corners). Jumps count as no frequency.
    pub fn frequency(&self, until: f64) -> f64 {
        const SAMPLES: usize = 1000;
        let (mut d, mut dd) = (0.0_f64, 0.0_f64);
        for k in 0..=SAMPLES {
            let j = self.jet(until * k as f64 / SAMPLES as f64);
            (d, dd) = (d.max(j.d.abs()), dd.max(j.dd.abs()));
        }
        let smooth = if d > 0.0 && dd.is_finite() {
            dd / d
        } else {
            0.0
        };
        let mut corners = 0.0_f64;
        self.each_piecewise(&mut |knots| {
            for w in knots.windows(2) {
                let gap = w[1].0 - w[0].0;
                if gap > 0.0 && w[0].0 < until {
                    corners = corners.max(2.0 * std::f64::consts::PI / gap);
                }
            }
        });
        smooth.max(corners)
    }

    /// The times of the knots of every piecewise function in the tree (where such a function
    /// peaks), for sampling it.
    pub fn knot_times(&self) -> Vec<f64> {
        let mut out = Vec::new();
        self.each_piecewise(&mut |knots| out.extend(knots.iter().map(|k| k.0)));
        out
    }

    /// Calls `visit` with the knots of every piecewise function in the tree.
    fn each_piecewise(&self, visit: &mut dyn FnMut(&Knots)) {
        match self {
            TimeFn::Const { .. } | TimeFn::Time | TimeFn::Arc => {}
            TimeFn::Unary { arg, .. } | TimeFn::Pow { arg, .. } => arg.each_piecewise(visit),
            // Knots are times only when the argument is `t` itself.
            TimeFn::Piecewise { knots, arg, .. } => {
                if matches!(**arg, TimeFn::Time) {
                    visit(knots);
                }
                arg.each_piecewise(visit);
            }
            TimeFn::Binary { lhs, rhs, .. } => {
                lhs.each_piecewise(visit);
                rhs.each_piecewise(visit);
            }
        }
    }

    /// Whether any leaf of the tree satisfies `leaf`.
    fn depends(&self, leaf: &dyn Fn(&TimeFn) -> bool) -> bool {
        match self {
            TimeFn::Const { .. } | TimeFn::Time | TimeFn::Arc => leaf(self),
            TimeFn::Unary { arg, .. } | TimeFn::Pow { arg, .. } | TimeFn::Piecewise { arg, .. } => {
                arg.depends(leaf)
            }
            TimeFn::Binary { lhs, rhs, .. } => lhs.depends(leaf) || rhs.depends(leaf),
        }
    }

    /// The tree with each leaf for which `leaf` gives a replacement replaced.
    fn substitute(&self, leaf: &dyn Fn(&TimeFn) -> Option<TimeFn>) -> TimeFn {
        match self {
            TimeFn::Const { .. } | TimeFn::Time | TimeFn::Arc => {
                leaf(self).unwrap_or_else(|| self.clone())
            }
            TimeFn::Unary { op, arg } => TimeFn::Unary {
                op: *op,
                arg: Box::new(arg.substitute(leaf)),
            },
            TimeFn::Binary { op, lhs, rhs } => {
                TimeFn::binary(*op, lhs.substitute(leaf), rhs.substitute(leaf))
            }
            TimeFn::Pow { arg, exponent } => TimeFn::Pow {
                arg: Box::new(arg.substitute(leaf)),
                exponent: *exponent,
            },
            TimeFn::Piecewise {
                knots,
                outside,
                arg,
            } => TimeFn::Piecewise {
                knots: knots.clone(),
                outside: *outside,
                arg: Box::new(arg.substitute(leaf)),
            },
        }
    }

    pub fn eval(&self, t: f64) -> f64 {
        self.jet(t).v
    }

    /// Value, rate and acceleration at time `t`.
    pub fn jet(&self, t: f64) -> Jet {
        match self {
            TimeFn::Const { value } => Jet::constant(*value),
            TimeFn::Time => Jet {
                v: t,
                d: 1.0,
                dd: 0.0,
            },
            // Never reached in a run: the lowering replaces it (`at_arc`); NaN if it were.
            TimeFn::Arc => Jet::constant(f64::NAN),
            TimeFn::Unary { op, arg } => unary(*op, arg.jet(t)),
            TimeFn::Binary { op, lhs, rhs } => {
                let (a, b) = (lhs.jet(t), rhs.jet(t));
                match op {
                    Binary::Add => Jet {
                        v: a.v + b.v,
                        d: a.d + b.d,
                        dd: a.dd + b.dd,
                    },
                    Binary::Sub => Jet {
                        v: a.v - b.v,
                        d: a.d - b.d,
                        dd: a.dd - b.dd,
                    },
                    Binary::Mul => Jet {
                        v: a.v * b.v,
                        d: a.d * b.v + a.v * b.d,
                        dd: a.dd * b.v + 2.0 * a.d * b.d + a.v * b.dd,
                    },
                    Binary::Div => {
                        // q = a / b; q' = (a' - q b') / b; q'' = (a'' - 2 q' b' - q b'') / b
                        let q = a.v / b.v;
                        let q1 = (a.d - q * b.d) / b.v;
                        let q2 = (a.dd - 2.0 * q1 * b.d - q * b.dd) / b.v;
                        Jet {
                            v: q,
                            d: q1,
                            dd: q2,
                        }
                    }
                    Binary::Atan2 => {
                        // atan2(y = a, x = b)
                        let r2 = a.v * a.v + b.v * b.v;
                        let n = b.v * a.d - a.v * b.d;
                        let n1 = b.v * a.dd - a.v * b.dd;
                        let r21 = 2.0 * (a.v * a.d + b.v * b.d);
                        Jet {
                            v: a.v.atan2(b.v),
                            d: n / r2,
                            dd: (n1 * r2 - n * r21) / (r2 * r2),
                        }
                    }
                    Binary::Min => {
                        if a.v <= b.v {
                            a
                        } else {
                            b
                        }
                    }
                    Binary::Max => {
                        if a.v >= b.v {
                            a
                        } else {
                            b
                        }
                    }
                }
            }
            TimeFn::Pow { arg, exponent } => {
                let a = arg.jet(t);
                let p = *exponent;
                let x = a.v;
                a.chain(
                    x.powf(p),
                    p * x.powf(p - 1.0),
                    p * (p - 1.0) * x.powf(p - 2.0),
                )
            }
            TimeFn::Piecewise {
                knots,
                outside,
                arg,
            } => {
                let a = arg.jet(t);
                let (v, slope) = piecewise(knots, *outside, a.v);
                a.chain(v, slope, 0.0)
            }
        }
    }
}

/// A unary function's jet from its argument's.
fn unary(op: Unary, a: Jet) -> Jet {
    let x = a.v;
    match op {
        Unary::Sin => a.chain(x.sin(), x.cos(), -x.sin()),
        Unary::Cos => a.chain(x.cos(), -x.sin(), -x.cos()),
        Unary::Tan => {
            let c2 = 1.0 / (x.cos() * x.cos());
            a.chain(x.tan(), c2, 2.0 * x.tan() * c2)
        }
        Unary::Asin => {
            let s = 1.0 - x * x;
            a.chain(x.asin(), 1.0 / s.sqrt(), x / (s * s.sqrt()))
        }
        Unary::Acos => {
            let s = 1.0 - x * x;
            a.chain(x.acos(), -1.0 / s.sqrt(), -x / (s * s.sqrt()))
        }
        Unary::Atan => {
            let s = 1.0 + x * x;
            a.chain(x.atan(), 1.0 / s, -2.0 * x / (s * s))
        }
        Unary::Sqrt => {
            let r = x.sqrt();
            a.chain(r, 0.5 / r, -0.25 / (r * x))
        }
        Unary::Abs => {
            let s = if x < 0.0 { -1.0 } else { 1.0 };
            a.chain(x.abs(), s, 0.0)
        }
        Unary::Exp => a.chain(x.exp(), x.exp(), x.exp()),
        Unary::Ln => a.chain(x.ln(), 1.0 / x, -1.0 / (x * x)),
    }
}

/// Value and slope of a piecewise-linear function at `x`.
fn piecewise(knots: &[(f64, f64)], outside: Outside, x: f64) -> (f64, f64) {
    let Some(&(t0, v0)) = knots.first() else {
        return (0.0, 0.0);
    };
    let &(tn, vn) = knots.last().unwrap_or(&(t0, v0));
    if knots.len() == 1 {
        return (v0, 0.0);
    }
    let slope_of = |k: usize| {
        let (a, b) = (knots[k], knots[k + 1]);
        if b.0 > a.0 {
            (b.1 - a.1) / (b.0 - a.0)
        } else {
            0.0
        }
    };
    let mut x = x;
    if outside == Outside::Periodic && tn > t0 {
        x = t0 + (x - t0).rem_euclid(tn - t0);
    }
    if x < t0 {
        return match outside {
            Outside::Extrapolate => {
                let s = slope_of(0);
                (v0 + s * (x - t0), s)
            }
            _ => (v0, 0.0),
        };
    }
    if x >= tn {
        return match outside {
            Outside::Extrapolate => {
                let s = slope_of(knots.len() - 2);
                (vn + s * (x - tn), s)
            }
            _ => (vn, 0.0),
        };
    }
    // The last knot with t_k <= x: at a jump the later value holds.
    let k = knots.partition_point(|&(tk, _)| tk <= x).saturating_sub(1);
    let k = k.min(knots.len() - 2);
    let (a, b) = (knots[k], knots[k + 1]);
    if b.0 > a.0 {
        let s = (b.1 - a.1) / (b.0 - a.0);
        (a.1 + s * (x - a.0), s)
    } else {
        (b.1, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t() -> TimeFn {
        TimeFn::Time
    }

    /// Central differences of the value and of the rate check the jet.
    fn check_jet(f: &TimeFn, at: &[f64]) {
        let h = 1e-5;
        for &x in at {
            let j = f.jet(x);
            let d = (f.eval(x + h) - f.eval(x - h)) / (2.0 * h);
            let dd = (f.jet(x + h).d - f.jet(x - h).d) / (2.0 * h);
            assert!(
                (j.d - d).abs() < 1e-6 * (1.0 + d.abs()),
                "d at {x}: {} vs {d}",
                j.d
            );
            assert!(
                (j.dd - dd).abs() < 1e-5 * (1.0 + dd.abs()),
                "dd at {x}: {} vs {dd}",
                j.dd
            );
        }
    }

    #[test]
    fn derivatives_match_central_differences() {
        let s = TimeFn::Unary {
            op: Unary::Sin,
            arg: Box::new(TimeFn::binary(Binary::Mul, TimeFn::constant(3.0), t())),
        };
        let e = TimeFn::Unary {
            op: Unary::Exp,
            arg: Box::new(TimeFn::binary(Binary::Mul, TimeFn::constant(-0.5), t())),
        };
        let q = TimeFn::binary(
            Binary::Div,
            s.clone(),
            TimeFn::binary(Binary::Add, TimeFn::constant(2.0), t()),
        );
        let p = TimeFn::Pow {
            arg: Box::new(TimeFn::binary(Binary::Add, TimeFn::constant(1.0), t())),
            exponent: 2.5,
        };
        let a = TimeFn::binary(
            Binary::Atan2,
            s.clone(),
            TimeFn::binary(Binary::Add, TimeFn::constant(1.5), e.clone()),
        );
        let r = TimeFn::Unary {
            op: Unary::Sqrt,
            arg: Box::new(TimeFn::binary(
                Binary::Add,
                TimeFn::constant(1.0),
                TimeFn::binary(Binary::Mul, t(), t()),
            )),
        };
        for f in [
            s.clone(),
            e.clone(),
            q,
            p,
            a,
            r,
            TimeFn::binary(Binary::Mul, s, e),
        ] {
            check_jet(&f, &[0.1, 0.7, 1.3, 2.9]);
        }
    }

    #[test]
    fn piecewise_holds_extrapolates_and_repeats() {
        let knots = vec![(0.0, 0.0), (10.0, 10.0), (20.0, 0.0)];
        let f = |outside| TimeFn::Piecewise {
            knots: knots.clone(),
            outside,
            arg: Box::new(TimeFn::Time),
        };
        let hold = f(Outside::Hold);
        assert_eq!(hold.eval(-1.0), 0.0);
        assert_eq!(hold.eval(5.0), 5.0);
        assert_eq!(hold.eval(15.0), 5.0);
        assert_eq!(hold.eval(25.0), 0.0);
        assert_eq!(hold.jet(5.0).d, 1.0);
        assert_eq!(hold.jet(15.0).d, -1.0);
        let ex = f(Outside::Extrapolate);
        assert_eq!(ex.eval(25.0), -5.0);
        assert_eq!(ex.eval(-2.0), -2.0);
        let per = f(Outside::Periodic);
        assert!((per.eval(25.0) - 5.0).abs() < 1e-12);
        // A jump: the later value holds at the knot.
        let step = TimeFn::Piecewise {
            knots: vec![(1.0, 0.0), (1.0, 2.0)],
            outside: Outside::Hold,
            arg: Box::new(TimeFn::Time),
        };
        assert_eq!(step.eval(0.999), 0.0);
        assert_eq!(step.eval(1.0), 2.0);
        assert_eq!(step.eval(3.0), 2.0);
    }

    #[test]
    fn composition_substitutes_time() {
        let f = TimeFn::binary(Binary::Mul, TimeFn::Time, TimeFn::Time);
        let g = TimeFn::binary(Binary::Sub, TimeFn::Time, TimeFn::constant(1.0));
        let h = f.compose(&g);
        assert_eq!(h.eval(3.0), 4.0);
        assert_eq!(h.jet(3.0).d, 4.0);
        assert_eq!(h.jet(3.0).dd, 2.0);
    }

    #[test]
    fn a_sine_has_its_frequency_a_ramp_none_and_corners_theirs() {
        let w = 7.0;
        let sine = TimeFn::Unary {
            op: Unary::Sin,
            arg: Box::new(TimeFn::binary(
                Binary::Mul,
                TimeFn::constant(w),
                TimeFn::Time,
            )),
        };
        // Over whole periods the sampled maxima are the amplitude's to 1e-4.
        let f = sine.frequency(2.0 * std::f64::consts::PI);
        assert!((f / w - 1.0).abs() < 1e-4, "{f}");
        let offset = TimeFn::binary(Binary::Add, TimeFn::constant(5.0), sine);
        assert!((offset.frequency(2.0 * std::f64::consts::PI) / w - 1.0).abs() < 1e-4);
        assert_eq!(TimeFn::Time.frequency(1.0), 0.0);
        assert_eq!(TimeFn::constant(3.0).frequency(1.0), 0.0);
        let pulse = TimeFn::Piecewise {
            knots: vec![(0.0, 0.0), (0.005, 20.0), (0.01, 0.0)],
            outside: Outside::Hold,
            arg: Box::new(TimeFn::Time),
        };
        let corners = 2.0 * std::f64::consts::PI / 0.005;
        assert!((pulse.frequency(3.0) / corners - 1.0).abs() < 1e-12);
        assert_eq!(pulse.knot_times(), vec![0.0, 0.005, 0.01]);
        // Knots after the run do not count.
        assert_eq!(pulse.frequency(-1.0), 0.0);
    }
}
