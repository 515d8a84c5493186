//! A beam's reference line through given points: a polyline, or a smooth curve (the cubic
//! spline through the points with not-a-knot ends, parametrized by chord length; a parabola
//! through three points); points along it by arc length, with the unit tangent there.
//! Contract: geometry only; must not know beams or diagnostics.

/// Gauss-Legendre points and weights on [-1, 1] for the arc length of each piece.
const GAUSS: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// Sub-intervals of each piece for the arc length table.
const SUB: usize = 32;

pub(super) struct Curve {
    /// Chord-length parameters of the points.
    t: Vec<f64>,
    points: Vec<[f64; 3]>,
    /// Second derivatives at the points (smooth), none for a polyline.
    second: Option<Vec<[f64; 3]>>,
    /// Arc length at the parameters `table[k].0`.
    table: Vec<(f64, f64)>,
}

/// `a - b`, its length.
fn chord(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

impl Curve {
    /// The curve through `points` (two or more, consecutive ones apart); `None` if two
    /// consecutive points coincide.
    pub(super) fn new(points: &[[f64; 3]], polyline: bool) -> Option<Curve> {
        let mut t = vec![0.0];
        for w in points.windows(2) {
            let c = chord(w[0], w[1]);
            if c <= 1e-12 * (1.0 + t[t.len() - 1]) {
                return None;
            }
            t.push(t[t.len() - 1] + c);
        }
        if points.len() < 2 {
            return None;
        }
        let second = (!polyline && points.len() > 2).then(|| spline(&t, points));
        let mut curve = Curve {
            t,
            points: points.to_vec(),
            second,
            table: Vec::new(),
        };
        curve.table = curve.arc_table();
        Some(curve)
    }

    /// The curve's length.
    pub(super) fn length(&self) -> f64 {
        self.table.last().map_or(0.0, |x| x.1)
    }

    /// The point at arc length `s` and the unit tangent there.
    pub(super) fn at(&self, s: f64) -> ([f64; 3], [f64; 3]) {
        let u = self.parameter(s);
        let (x, d) = self.eval(u);
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        (x, d.map(|c| c / n))
    }

    /// The piece of parameter `u` and the point and derivative there.
    fn eval(&self, u: f64) -> ([f64; 3], [f64; 3]) {
        let last = self.t.len() - 2;
        let i = self.t[1..]
            .iter()
            .position(|&ti| u <= ti)
            .unwrap_or(last)
            .min(last);
        let (t0, t1) = (self.t[i], self.t[i + 1]);
        let h = t1 - t0;
        let (p0, p1) = (self.points[i], self.points[i + 1]);
        match &self.second {
            None => {
                let f = (u - t0) / h;
                (
                    std::array::from_fn(|k| p0[k] + f * (p1[k] - p0[k])),
                    std::array::from_fn(|k| (p1[k] - p0[k]) / h),
                )
            }
            Some(m) => {
                let (a, b) = (t1 - u, u - t0);
                let (m0, m1) = (m[i], m[i + 1]);
                let x = std::array::from_fn(|k| {
                    m0[k] * a.powi(3) / (6.0 * h)
                        + m1[k] * b.powi(3) / (6.0 * h)
                        + (p0[k] / h - m0[k] * h / 6.0) * a
                        + (p1[k] / h - m1[k] * h / 6.0) * b
                });
                let d = std::array::from_fn(|k| {
                    -m0[k] * a * a / (2.0 * h) + m1[k] * b * b / (2.0 * h)
                        - (p0[k] / h - m0[k] * h / 6.0)
                        + (p1[k] / h - m1[k] * h / 6.0)
                });
                (x, d)
            }
        }
    }

    /// The arc length from parameter `a` over `h` (5-point Gauss).
    fn arc(&self, a: f64, h: f64) -> f64 {
        GAUSS
            .iter()
            .map(|&(x, wt)| {
                let d = self.eval(a + (x + 1.0) * h / 2.0).1;
                wt * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            })
            .sum::<f64>()
            * h
            / 2.0
    }

    /// Arc length at `SUB` sub-intervals of every piece (5-point Gauss on each).
    fn arc_table(&self) -> Vec<(f64, f64)> {
        let mut table = vec![(0.0, 0.0)];
        for w in self.t.windows(2) {
            let h = (w[1] - w[0]) / SUB as f64;
            for k in 0..SUB {
                let a = w[0] + k as f64 * h;
                let s = table[table.len() - 1].1 + self.arc(a, h);
                table.push((a + h, s));
            }
        }
        table
    }

    /// The parameter at arc length `s`: the table's interval, then Newton on the speed.
    fn parameter(&self, s: f64) -> f64 {
        let k = self
            .table
            .windows(2)
            .position(|w| s <= w[1].1)
            .unwrap_or(self.table.len() - 2);
        let ((u0, s0), (u1, s1)) = (self.table[k], self.table[k + 1]);
        let mut u = u0 + (s - s0) / (s1 - s0) * (u1 - u0);
        for _ in 0..4 {
            let len = self.arc(u0, u - u0);
            let d = self.eval(u).1;
            let speed = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            u -= (s0 + len - s) / speed;
        }
        u.clamp(self.t[0], self.t[self.t.len() - 1])
    }
}

/// The second derivatives of the cubic spline through `points` at parameters `t`, not-a-knot
/// at both ends (three points: the parabola through them).
fn spline(t: &[f64], points: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let n = t.len();
    let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
    let mut rhs = nalgebra::DMatrix::<f64>::zeros(n, 3);
    for i in 1..n - 1 {
        a[(i, i - 1)] = h[i - 1];
        a[(i, i)] = 2.0 * (h[i - 1] + h[i]);
        a[(i, i + 1)] = h[i];
        for k in 0..3 {
            rhs[(i, k)] = 6.0
                * ((points[i + 1][k] - points[i][k]) / h[i]
                    - (points[i][k] - points[i - 1][k]) / h[i - 1]);
        }
    }
    if n == 3 {
        // One parabola: equal second derivatives.
        a[(0, 0)] = 1.0;
        a[(0, 1)] = -1.0;
        a[(2, 1)] = -1.0;
        a[(2, 2)] = 1.0;
    } else {
        // Not-a-knot: the third derivative continuous at the second and the last but one.
        a[(0, 0)] = h[1];
        a[(0, 1)] = -(h[0] + h[1]);
        a[(0, 2)] = h[0];
        a[(n - 1, n - 3)] = h[n - 2];
        a[(n - 1, n - 2)] = -(h[n - 3] + h[n - 2]);
        a[(n - 1, n - 1)] = h[n - 3];
    }
    let m = a
        .lu()
        .solve(&rhs)
        .unwrap_or_else(|| nalgebra::DMatrix::zeros(n, 3));
    (0..n).map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]]).collect()
}
