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

/// For each body whose own inertia leaves motions free, a basis of those motions (in its own
/// columns, unit columns); and `top`, the largest squared norm of a row (the scale of the
/// tolerance). Shortness is judged in SI (the mass matrix `[m, m c~^T; m c~, J + m c~^T c~]`)
/// against the model's largest entry, not in the rows' scaled rotations: a small body far
/// from the origin is not short of inertia. Beam nodes never are (their mass matrix is full).
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
    // Rotation columns are scaled by 1/scale in the rows: back to SI.
    let si = |k: usize, i: usize| {
        if i >= 3 && cols.rotates[k] {
            r.scale
        } else {
            1.0
        }
    };
    for row in &r.rows[from..from + inertia] {
        for &(a, va) in row {
            for &(b, vb) in row {
                let k = node_of[a];
                let (i, j) = (a - cols.start[k], b - cols.start[k]);
                gram[k][(i, j)] += va * vb * si(k, i) * si(k, j);
            }
        }
    }
    let body = |k: usize| matches!(cols.nodes[k], Node::Body { .. });
    let eigs: Vec<_> = (0..cols.nodes.len())
        .map(|k| {
            let w = cols.width(k);
            SymmetricEigen::new(gram[k].view((0, 0), (w, w)).into_owned())
        })
        .collect();
    let largest = eigs
        .iter()
        .flat_map(|e| e.eigenvalues.iter().copied())
        .fold(0.0f64, f64::max);
    let tol = 1e-12 * largest.max(1e-300);
    let short = (0..cols.nodes.len())
        .map(|k| {
            let eig = &eigs[k];
            let w = cols.width(k);
            let free: Vec<usize> = (0..w).filter(|&q| eig.eigenvalues[q] <= tol).collect();
            (body(k) && !free.is_empty()).then(|| {
                // In the rows' columns: rotations times `scale`, each column of unit length.
                let mut b = DMatrix::from_fn(w, free.len(), |i, q| {
                    eig.eigenvectors[(i, free[q])] * si(k, i)
                });
                for mut c in b.column_iter_mut() {
                    let n = c.norm();
                    c /= n;
                }
                b
            })
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
    let (basis, top) = short_of_inertia(r, &node_of, from, inertia);
    let tol = 1e-12 * top.max(1e-30) * n as f64;
    let held = held(r, &node_of, &basis, tol);
    let short: Vec<bool> = (0..cols.nodes.len())
        .map(|k| basis[k].is_some() && !held[k])
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
        // A null vector moves each node within its free motions: `v_k = N_k z_k`.
        let mut at = std::collections::HashMap::new();
        let mut width = 0;
        for &k in &nodes {
            at.insert(k, width);
            width += basis[k].as_ref().map_or(0, |b| b.ncols());
        }
        if width > MAX_GROUP {
            unchecked(model, cols.nodes[nodes[0]], nodes.len(), width, sink);
            continue;
        }
        let mut a = DMatrix::<f64>::zeros(rows.len(), width);
        for (i, row) in rows.iter().enumerate() {
            for &(c, v) in row.iter() {
                let k = node_of[c];
                if let Some(b) = &basis[k] {
                    for q in 0..b.ncols() {
                        a[(i, at[&k] + q)] += v * b[(c - cols.start[k], q)];
                    }
                }
            }
        }
        let eig = SymmetricEigen::new(a.transpose() * &a);
        let Some(c) = (0..width).find(|&c| eig.eigenvalues[c].abs() <= tol) else {
            continue;
        };
        let z = eig.eigenvectors.column(c);
        let motion = |k: usize| -> Vec<f64> {
            let b = basis[k].as_ref().expect("a short node");
            (0..b.nrows())
                .map(|i| (0..b.ncols()).map(|q| b[(i, q)] * z[at[&k] + q]).sum())
                .collect()
        };
        // The node that moves most in this motion, and how.
        let (k, _) = nodes
            .iter()
            .map(|&k| (k, motion(k).iter().map(|x| x * x).sum::<f64>()))
            .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
        let v = motion(k);
        let t = [v[0], v[1], v[2]];
        let rot = if cols.rotates[k] {
            [v[3], v[4], v[5]]
        } else {
            [0.0; 3]
        };
        report(model, cols.nodes[k], t, rot, sink);
        return;
    }
}

/// Most free motions a group of bodies short of inertia may have for the dense check (a
/// matrix of this order, seconds to factor).
const MAX_GROUP: usize = 3000;

/// W0302: a group of bodies short of inertia, coupled to each other but not held one by one,
/// too large for the dense check.
fn unchecked(model: &Model, first: Node, bodies: usize, width: usize, sink: &mut Sink) {
    let (name, span) = named(model, first);
    sink.push(
        Diagnostic::warning(Code::W0302, format!("{bodies} bodies short of inertia, from `{name}` on, were not checked for motions without inertia or restraint ({width} free motions, over {MAX_GROUP})"))
            .at(span, "the first of them")
            .hint("give these bodies mass and inertia, or hold each by a joint to something that has; if a motion is free after all, the run stops with a singular iteration matrix (E0602) naming where"),
    );
}

/// The body or beam a node belongs to: its name and declaration.
fn named(model: &Model, node: Node) -> (String, crate::source::Span) {
    match node {
        Node::Body { body } => (model.bodies[body].name.clone(), model.bodies[body].span),
        Node::BeamNode { beam, .. } => (model.beams[beam].name.clone(), model.beams[beam].span),
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
    let (name, span) = named(model, node);
    sink.push(
        Diagnostic::error(Code::E0308, format!("`{name}` can move without inertia or restraint: {motion}"))
            .at(span, "declared here")
            .hint("give this motion mass or inertia, or hold it with a joint or a spring; otherwise the iteration matrix is singular"),
    );
}
