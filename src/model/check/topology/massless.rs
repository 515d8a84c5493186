//! Motions with neither inertia nor restraint (E0308): rows of inertia (the square root of
//! each node's mass matrix) and of springs, stacked under the constraints; a null vector is a
//! motion nothing resists. A node whose own inertia rows have full rank takes no part in one,
//! so only the nodes short of inertia are checked, in groups that rows couple, each dense.
//! Contract: reads the model; must not change it.

use super::*;

/// Reports the first motion nothing resists.
pub(super) fn check(model: &Model, r: &mut Rows, sink: &mut Sink) {
    if r.cols.n == 0 {
        return;
    }
    let from = r.rows.len();
    inertia_rows(model, r);
    let inertia = r.rows.len() - from;
    restraint_rows(model, r);
    unrestrained(model, r, from, inertia, sink);
}

/// `sqrt(M)` of every body and the unit rows of beam nodes (their mass matrix is full).
fn inertia_rows(model: &Model, r: &mut Rows) {
    let cols = r.cols;
    let scale = r.scale;
    for (body, b) in model.bodies.iter().enumerate() {
        let s = cols.start[cols.of(Node::Body { body })];
        let sm = b.mass.sqrt();
        let c = crate::model::eval::mat_vec(b.orientation, b.center);
        for i in 0..3 {
            // sqrt(m) (du + dtheta x c)_i
            let mut row = vec![(s + i, sm)];
            if b.kind == BodyKind::Rigid {
                let e = E[i];
                let rc = cross(c, e);
                for k in 0..3 {
                    row.push((s + 3 + k, sm * rc[k] / scale));
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
                let row = (0..3)
                    .map(|k| (s + 3 + k, l * eig.eigenvectors[(k, q)] / scale))
                    .collect();
                r.rows.push(row);
            }
        }
    }
    for (beam, b) in model.beams.iter().enumerate() {
        for node in 0..b.nodes.len() {
            let s = cols.start[cols.of(Node::BeamNode { beam, node })];
            for i in 0..6 {
                r.rows.push(vec![(s + i, 1.0)]);
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

/// For each node whose own inertia rows leave motions free, an orthonormal basis of those
/// motions (in its own columns); and `top`, the largest squared norm of a row (the scale of
/// the tolerance).
fn short_of_inertia(
    r: &Rows,
    node_of: &[usize],
    from: usize,
    inertia: usize,
) -> (Vec<Option<DMatrix<f64>>>, f64) {
    let cols = r.cols;
    let top = r.rows.iter().fold(0.0f64, |t, row| {
        t.max(row.iter().map(|(_, v)| v * v).sum::<f64>())
    });
    let mut gram = vec![nalgebra::Matrix6::<f64>::zeros(); cols.nodes.len()];
    for row in &r.rows[from..from + inertia] {
        for &(a, va) in row {
            for &(b, vb) in row {
                let k = node_of[a];
                gram[k][(a - cols.start[k], b - cols.start[k])] += va * vb;
            }
        }
    }
    let tol = 1e-12 * top.max(1e-30) * cols.n as f64;
    let short = (0..cols.nodes.len())
        .map(|k| {
            let w = cols.width(k);
            let eig = SymmetricEigen::new(gram[k].view((0, 0), (w, w)).into_owned());
            let free: Vec<usize> = (0..w).filter(|&q| eig.eigenvalues[q] <= tol).collect();
            (!free.is_empty())
                .then(|| DMatrix::from_fn(w, free.len(), |i, q| eig.eigenvectors[(i, free[q])]))
        })
        .collect();
    (short, top)
}

/// Which short nodes the rows hold still: a node whose free motions are all locked by rows
/// that touch no other short node still free cannot move in a null vector; holding it may
/// free its neighbours' rows in turn (a chain pinned at one end peels from that end, in time
/// linear in its length).
fn held(r: &Rows, node_of: &[usize], short: &[Option<DMatrix<f64>>], tol: f64) -> Vec<bool> {
    let cols = r.cols;
    let nn = cols.nodes.len();
    // The short nodes each row touches, and the rows touching each short node.
    let touches: Vec<Vec<usize>> = r
        .rows
        .iter()
        .map(|row| {
            let mut t: Vec<usize> = row
                .iter()
                .map(|&(c, _)| node_of[c])
                .filter(|&k| short[k].is_some())
                .collect();
            t.sort_unstable();
            t.dedup();
            t
        })
        .collect();
    let mut rows_of = vec![Vec::new(); nn];
    for (i, t) in touches.iter().enumerate() {
        for &k in t {
            rows_of[k].push(i);
        }
    }
    let mut held = vec![false; nn];
    let mut queued: Vec<bool> = short.iter().map(|b| b.is_some()).collect();
    let mut queue: std::collections::VecDeque<usize> = (0..nn).filter(|&k| queued[k]).collect();
    while let Some(k) = queue.pop_front() {
        queued[k] = false;
        let Some(basis) = &short[k] else { continue };
        if held[k] {
            continue;
        }
        let d = basis.ncols();
        let mut g = DMatrix::<f64>::zeros(d, d);
        for &i in &rows_of[k] {
            if touches[i].iter().any(|&o| o != k && !held[o]) {
                continue;
            }
            let mut p = nalgebra::DVector::<f64>::zeros(d);
            for &(c, v) in r.rows[i].iter().filter(|&&(c, _)| node_of[c] == k) {
                p += basis.row(c - cols.start[k]).transpose() * v;
            }
            g += &p * p.transpose();
        }
        if SymmetricEigen::new(g).eigenvalues.iter().all(|&e| e > tol) {
            held[k] = true;
            for &i in &rows_of[k] {
                for &o in &touches[i] {
                    if !held[o] && !queued[o] {
                        queued[o] = true;
                        queue.push_back(o);
                    }
                }
            }
        }
    }
    held
}

/// The null vectors of the stacked rows, on the nodes short of inertia, in groups that rows
/// couple: the node that moves most in the first one, and how.
fn unrestrained(model: &Model, r: &Rows, from: usize, inertia: usize, sink: &mut Sink) {
    let cols = r.cols;
    let n = cols.n;
    let mut node_of = vec![0usize; n];
    for k in 0..cols.nodes.len() {
        node_of[cols.start[k]..cols.start[k] + cols.width(k)].fill(k);
    }
    let (short, top) = short_of_inertia(r, &node_of, from, inertia);
    let tol = 1e-12 * top.max(1e-30) * n as f64;
    let held = held(r, &node_of, &short, tol);
    let short: Vec<bool> = (0..cols.nodes.len())
        .map(|k| short[k].is_some() && !held[k])
        .collect();
    if !short.iter().any(|&s| s) {
        return;
    }
    // Rows restricted to the short nodes' columns, grouped by the nodes they couple.
    let mut sets = super::blocks::UnionFind::new(cols.nodes.len());
    let mut touching: Vec<(usize, Row)> = Vec::new();
    for row in &r.rows {
        let kept: Row = row
            .iter()
            .copied()
            .filter(|&(c, _)| short[node_of[c]])
            .collect();
        if let Some(&(c0, _)) = kept.first() {
            for &(c, _) in &kept {
                sets.union(node_of[c0], node_of[c]);
            }
            touching.push((node_of[c0], kept));
        }
    }
    let mut groups: std::collections::BTreeMap<usize, (Vec<usize>, Vec<&Row>)> = Default::default();
    for k in (0..cols.nodes.len()).filter(|&k| short[k]) {
        groups.entry(sets.find(k)).or_default().0.push(k);
    }
    for (k, row) in &touching {
        if let Some(g) = groups.get_mut(&sets.find(*k)) {
            g.1.push(row);
        }
    }
    let mut groups: Vec<_> = groups.into_values().collect();
    groups.sort_by_key(|g| g.0[0]);
    for (nodes, rows) in groups {
        // The group's columns in node order, so a null vector reads node by node.
        let mut local = vec![usize::MAX; n];
        let mut width = 0;
        for &k in &nodes {
            for c in cols.start[k]..cols.start[k] + cols.width(k) {
                local[c] = width;
                width += 1;
            }
        }
        let mut a = DMatrix::<f64>::zeros(rows.len(), width);
        for (i, row) in rows.iter().enumerate() {
            for &(c, v) in row.iter() {
                a[(i, local[c])] += v;
            }
        }
        let eig = SymmetricEigen::new(a.transpose() * &a);
        let Some(c) = (0..width).find(|&c| eig.eigenvalues[c].abs() <= tol) else {
            continue;
        };
        let v = eig.eigenvectors.column(c);
        let at = |k: usize| local[cols.start[k]];
        // The node that moves most in this motion, and how.
        let (k, _) = nodes
            .iter()
            .map(|&k| {
                let s = at(k);
                (
                    k,
                    (0..cols.width(k)).map(|i| v[s + i] * v[s + i]).sum::<f64>(),
                )
            })
            .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
        let s = at(k);
        let t = [v[s], v[s + 1], v[s + 2]];
        let rot = if cols.rotates[k] {
            [v[s + 3], v[s + 4], v[s + 5]]
        } else {
            [0.0; 3]
        };
        report(model, cols.nodes[k], t, rot, sink);
        return;
    }
}

/// E0308 for a motion of `node`: its translation and rotation parts.
fn report(model: &Model, node: Node, t: [f64; 3], rot: [f64; 3], sink: &mut Sink) {
    let describe = |x: [f64; 3]| {
        // Either sign is the same motion: the largest component positive.
        let big = x
            .iter()
            .fold(0.0f64, |b, &v| if v.abs() > b.abs() { v } else { b });
        let n = norm(x) * big.signum();
        let c = |v: f64| if (v / n).abs() < 5e-4 { 0.0 } else { v / n };
        format!("({:.3}, {:.3}, {:.3})", c(x[0]), c(x[1]), c(x[2]))
    };
    let motion = if norm(rot) >= norm(t) {
        format!("rotation about {}", describe(rot))
    } else {
        format!("translation along {}", describe(t))
    };
    let (name, span) = match node {
        Node::Body { body } => (model.bodies[body].name.clone(), model.bodies[body].span),
        Node::BeamNode { beam, .. } => (model.beams[beam].name.clone(), model.beams[beam].span),
    };
    sink.push(
        Diagnostic::error(Code::E0308, format!("`{name}` can move without inertia or restraint: {motion}"))
            .at(span, "declared here")
            .hint("give this motion mass or inertia, or hold it with a joint or a spring; otherwise the iteration matrix is singular"),
    );
}
