//! Motions with neither inertia nor restraint (E0308): rows of inertia (the square root of
//! each node's mass matrix) and of springs, stacked under the constraints; a null vector is a
//! motion nothing resists. Contract: reads the model; must not change it.

use super::*;

/// Reports the first motion nothing resists.
pub(super) fn check(model: &Model, r: &mut Rows, sink: &mut Sink) {
    let n = r.cols.n;
    if n == 0 || n > MAX_DENSE {
        return;
    }
    inertia_rows(model, r);
    restraint_rows(model, r);
    unrestrained(model, r, sink);
}

/// `sqrt(M)` of every body and the unit rows of beam nodes (their mass matrix is full).
fn inertia_rows(model: &Model, r: &mut Rows) {
    let cols = r.cols;
    let n = cols.n;
    let scale = r.scale;
    for (body, b) in model.bodies.iter().enumerate() {
        let s = cols.start[cols.of(Node::Body { body })];
        let sm = b.mass.sqrt();
        let c = crate::model::eval::mat_vec(b.orientation, b.center);
        for i in 0..3 {
            // sqrt(m) (du + dtheta x c)_i
            let mut row = vec![0.0; n];
            row[s + i] = sm;
            if b.kind == BodyKind::Rigid {
                let e = E[i];
                let rc = cross(c, e);
                for k in 0..3 {
                    row[s + 3 + k] = sm * rc[k] / scale;
                }
            }
            r.rows.push(row);
        }
        if b.kind == BodyKind::Rigid {
            let rot = crate::model::eval::mat_mul(
                crate::model::eval::mat_mul(b.orientation, b.inertia),
                crate::model::eval::transpose(b.orientation),
            );
            let eig = SymmetricEigen::new(nalgebra::Matrix3::from_fn(|i, k| rot[i][k]));
            for q in 0..3 {
                let l = eig.eigenvalues[q].max(0.0).sqrt();
                let mut row = vec![0.0; n];
                for k in 0..3 {
                    row[s + 3 + k] = l * eig.eigenvectors[(k, q)] / scale;
                }
                r.rows.push(row);
            }
        }
    }
    for (beam, b) in model.beams.iter().enumerate() {
        for node in 0..b.nodes.len() {
            let s = cols.start[cols.of(Node::BeamNode { beam, node })];
            for i in 0..6 {
                let mut row = vec![0.0; n];
                row[s + i] = 1.0;
                r.rows.push(row);
            }
        }
    }
}

/// Springs and dampers, and joint springs, restrain the motions they act on.
fn restraint_rows(model: &Model, r: &mut Rows) {
    for sp in &model.springs {
        if sp.stiffness <= 0.0 && sp.damping <= 0.0 {
            continue;
        }
        match sp.kind {
            SpringKind::Linear => {
                let d = sub(sp.markers[1].position, sp.markers[0].position);
                if norm(d) > 0.0 {
                    r.lock_translation(&sp.markers, d.map(|x| x / norm(d)));
                }
            }
            SpringKind::Torsional => E.iter().for_each(|e| r.lock_rotation(&sp.markers, *e)),
        }
    }
    // Joint springs restrain the joint's free motion too.
    for j in &model.joints {
        match &j.kind {
            JointKind::Revolute {
                axis,
                spring,
                damper,
                ..
            } if *spring > 0.0 || *damper > 0.0 => r.lock_rotation(&j.markers, *axis),
            JointKind::Prismatic {
                axis,
                spring,
                damper,
                ..
            } if *spring > 0.0 || *damper > 0.0 => r.lock_translation(&j.markers, *axis),
            _ => {}
        }
    }
}

/// The null vectors of the stacked rows: the node that moves most in one, and how.
fn unrestrained(model: &Model, r: &Rows, sink: &mut Sink) {
    let cols = r.cols;
    let n = cols.n;
    let m = r.rows.len();
    let a = DMatrix::from_fn(m, n, |i, k| r.rows[i][k]);
    let ata = a.transpose() * &a;
    let eig = SymmetricEigen::new(ata);
    let top = eig.eigenvalues.iter().fold(0.0f64, |x, y| x.max(y.abs()));
    let tol = 1e-12 * top.max(1e-30) * n as f64;
    for c in 0..n {
        if eig.eigenvalues[c].abs() > tol {
            continue;
        }
        let v = eig.eigenvectors.column(c);
        // The node that moves most in this motion, and how.
        let (k, _) = (0..cols.nodes.len())
            .map(|k| {
                let s = cols.start[k];
                let w = if cols.rotates[k] { 6 } else { 3 };
                (k, (0..w).map(|i| v[s + i] * v[s + i]).sum::<f64>())
            })
            .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
        let s = cols.start[k];
        let t = [v[s], v[s + 1], v[s + 2]];
        let rot = if cols.rotates[k] {
            [v[s + 3], v[s + 4], v[s + 5]]
        } else {
            [0.0; 3]
        };
        let describe = |x: [f64; 3]| {
            let n = norm(x);
            let c = |v: f64| if (v / n).abs() < 5e-4 { 0.0 } else { v / n };
            format!("({:.3}, {:.3}, {:.3})", c(x[0]), c(x[1]), c(x[2]))
        };
        let motion = if norm(rot) >= norm(t) {
            format!("rotation about {}", describe(rot))
        } else {
            format!("translation along {}", describe(t))
        };
        let (name, span) = match cols.nodes[k] {
            Node::Body { body } => (model.bodies[body].name.clone(), model.bodies[body].span),
            Node::BeamNode { beam, .. } => (model.beams[beam].name.clone(), model.beams[beam].span),
        };
        sink.push(
            Diagnostic::error(Code::E0308, format!("`{name}` can move without inertia or restraint: {motion}"))
                .at(span, "declared here")
                .hint("give this motion mass or inertia, or hold it with a joint or a spring; otherwise the iteration matrix is singular"),
        );
        return;
    }
}
