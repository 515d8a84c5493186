//! A joint's iteration matrix: every row's force derivative (its geometric stiffness and the
//! penalty's `p grad G grad G^T`) and its equation's gradient; with the residual at the same
//! state when the caller needs both, each row's geometry made once.

use super::{add_force, globals, slots, Geo, Grad, Hess, Joint, Spreads, SLOTS};
use crate::runtime::{Augment, Residual, State, TangentCoeffs};

impl Joint {
    /// [`Joint::residual`] into `r` and [`Joint::tangent`] into `k` at one state, each row's
    /// geometry made once for both (ends between beam nodes: the two one after the other).
    pub fn residual_and_tangent(
        &self,
        st: &State,
        aug: Augment,
        c: TangentCoeffs,
        r: &mut Residual,
        k: &mut [f64],
    ) {
        if self.a.is_between() || self.b.is_between() {
            self.residual_between(st, aug, r);
            self.tangent_with(st, aug, c, k, None);
        } else {
            self.tangent_with(st, aug, c, k, Some(r));
        }
    }

    pub fn tangent(&self, st: &State, aug: Augment, c: TangentCoeffs, k: &mut [f64]) {
        self.tangent_with(st, aug, c, k, None);
    }

    /// [`Joint::tangent`], and with `res` (plain ends only) [`Joint::residual`] into it.
    fn tangent_with(
        &self,
        st: &State,
        aug: Augment,
        c: TangentCoeffs,
        k: &mut [f64],
        mut res: Option<&mut Residual>,
    ) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        // `res` comes only with plain ends.
        let glob = match res {
            Some(_) => globals(&self.a, &self.b, self.angle),
            None => [None; SLOTS],
        };
        let (map, m0) = slots(&self.a, &self.b, self.angle);
        // Ends between beam nodes reach several unknowns per slot.
        let spread = (self.a.is_between() || self.b.is_between())
            .then(|| Spreads::new(&self.a, &self.b, self.angle, st));
        let nl = m0 + self.rows.len();
        k[..nl * nl].iter_mut().for_each(|x| *x = 0.0);
        let w = c.force_weight;
        // The slots this joint assembles, with their local positions (plain ends).
        let mut live = [(0usize, 0usize); SLOTS];
        let mut nlive = 0;
        for (s, l) in map.iter().enumerate() {
            if let Some(l) = l {
                live[nlive] = (s, *l);
                nlive += 1;
            }
        }
        let live = &live[..nlive];
        // Every row's geometric stiffness and the penalty's `p grad G grad G^T`, summed over
        // the rows and assembled once with the weight `w c_q`.
        let mut h = [[0.0; SLOTS]; SLOTS];
        for (r, row) in self.rows.iter().enumerate() {
            let m = m0 + r;
            if self.is_dropped(r, st) {
                k[m * nl + m] = aug.s;
                if let Some(res) = res.as_deref_mut() {
                    res.constraint[self.first + r] = st.lambda[self.first + r];
                }
                continue;
            }
            let (gv, gr) = row.geom(&geo);
            let lam = st.lambda[self.first + r];
            let f = row.drive().map_or(0.0, |f| f.eval(st.t));
            if let Some(res) = res.as_deref_mut() {
                let row_at = self.first + r;
                let mu = Self::row_equation(row_at, row, (gv, &gr, f), &geo, st, aug, res);
                add_force(&glob, mu, &gr, res);
            }
            // The row's derivative over the slots (a rate row's through the velocities too:
            // its `s B` part).
            let mut dc = [0.0; SLOTS];
            if row.is_rate() {
                row.hess(&geo, aug.s * lam, &mut h);
                let mut h1 = [[0.0; SLOTS]; SLOTS];
                row.hess(&geo, 1.0, &mut h1);
                for &(sj, _) in live {
                    let vh: f64 = (0..SLOTS).map(|si| geo.vel[si] * h1[si][sj]).sum();
                    // `rate_scale` is `1 / velocity` (the integrator's `beta h / gamma`): the
                    // row is `s (B + rate_scale position V^T H)`, a unit-weight `s B` in the
                    // constrained mass matrix too.
                    dc[sj] = aug.s * (gr[sj] + aug.rate_scale * c.position * vh);
                }
            } else {
                row.hess(&geo, aug.s * lam + aug.p * (gv - f), &mut h);
                for &(sj, _) in live {
                    dc[sj] = aug.s * gr[sj];
                }
                add_penalty(live, aug.p, &gr, &mut h);
            }
            match &spread {
                None => {
                    for &(s, l) in live {
                        k[m * nl + l] = dc[s];
                        k[l * nl + m] = w * aug.s * gr[s];
                    }
                }
                Some(sp) => {
                    for &(s, _) in live {
                        // The velocities' part through their interpolation.
                        let dv = if row.is_rate() { aug.s * gr[s] } else { 0.0 };
                        for (l, cl) in sp.trial[s].iter() {
                            k[m * nl + l] += (dc[s] - dv) * cl;
                        }
                        for (l, cl) in sp.rate[s].iter() {
                            k[m * nl + l] += dv * cl;
                        }
                        for (l, cl) in sp.test[s].iter() {
                            k[l * nl + m] += w * aug.s * gr[s] * cl;
                        }
                    }
                }
            }
        }
        let wc = w * c.position;
        match &spread {
            None => {
                for &(si, li) in live {
                    for &(sj, lj) in live {
                        k[li * nl + lj] += wc * h[si][sj];
                    }
                }
            }
            Some(sp) => sp.add_matrix(&h, wc, false, k, nl),
        }
    }
}

/// Adds the penalty's outer product `p grad grad^T` to `h` over the live slots the row reaches
/// (a row reaches 1 to 8 of the 13).
#[inline(always)]
fn add_penalty(live: &[(usize, usize)], p: f64, gr: &Grad, h: &mut Hess) {
    let mut reach = [0usize; SLOTS];
    let mut nr = 0;
    for &(si, _) in live {
        if gr[si] != 0.0 {
            reach[nr] = si;
            nr += 1;
        }
    }
    for &si in &reach[..nr] {
        let g = p * gr[si];
        for &sj in &reach[..nr] {
            h[si][sj] += g * gr[sj];
        }
    }
}
