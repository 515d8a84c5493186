//! What a joint reports: its rows' forces, its violation, its reaction on end B, a
//! prismatic joint's slide.

use super::{along, dot13, Geo, Joint, SLOTS, TB, UB};
use crate::runtime::rotation::V3;
use crate::runtime::{Augment, State};

impl Joint {
    /// The physical force `mu` of row `row`.
    pub fn multiplier_force(&self, st: &State, aug: Augment, row: usize) -> f64 {
        let m = self.first + row;
        if self.is_dropped(row, st) {
            0.0
        } else if self.rows[row].is_rate() {
            aug.s * st.lambda[m]
        } else {
            aug.s * st.lambda[m] + aug.p * self.violation_row(st, row)
        }
    }

    pub(super) fn violation_row(&self, st: &State, row: usize) -> f64 {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let r = &self.rows[row];
        let f = r.drive().map_or(0.0, |f| f.eval(st.t));
        let (gv, gr) = r.geom(&geo);
        if r.is_rate() {
            dot13(&gr, &geo.vel) - f
        } else {
            gv - f
        }
    }

    /// The largest constraint violation (position rows; rate rows in their own units).
    pub fn violation(&self, st: &State) -> f64 {
        (0..self.rows.len())
            .map(|r| self.violation_row(st, r).abs())
            .fold(0.0, f64::max)
    }

    /// The force and the moment (about the marker point) that the joint applies on end B,
    /// inertial components.
    pub fn reaction(&self, st: &State, aug: Augment) -> (V3, V3) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let (mut f, mut m) = (V3::zeros(), V3::zeros());
        for (r, row) in self.rows.iter().enumerate() {
            let mu = self.multiplier_force(st, aug, r);
            let (_, gr) = row.geom(&geo);
            f -= V3::new(gr[UB], gr[UB + 1], gr[UB + 2]) * mu;
            m -= V3::new(gr[TB], gr[TB + 1], gr[TB + 2]) * mu;
        }
        (f, m - geo.b.p.cross(&f))
    }

    /// A prismatic joint's displacement and speed along its axis.
    pub fn slide(&self, st: &State) -> (f64, f64) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let mut gr = [0.0; SLOTS];
        let x = along(&geo, 2, self.slide_offset.unwrap_or(0.0), &mut gr);
        (x, dot13(&gr, &geo.vel))
    }
}
