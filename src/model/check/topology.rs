//! Topology checks at the initial configuration, before anything runs:
//! - bodies with no path to ground (warning W0301, naming the free motions);
//! - joints that lock rotations of a point mass, which has none (E0306);
//! - redundant or contradictory constraints: the rank of the constraint Jacobian (E0307),
//!   naming the joints whose equations are dependent;
//! - motions with neither inertia nor restraint, which make the iteration matrix singular
//!   (E0308), such as a massless body held by nothing.
//!
//! The Jacobian is taken with respect to virtual displacements and rotations of every node,
//! which has the rank of the Jacobian in any rotation parameters.
//!
//! Contract: reads a complete model and reports; must not change it, nor know the runtime.

use super::dofs::{attach_nodes, Node};
use crate::diagnostics::{Code, Diagnostic, Sink};
use crate::model::build::{cross, norm, sub};
use crate::model::*;
use nalgebra::{DMatrix, SymmetricEigen};

mod blocks;
mod massless;
mod report;
mod tree;

pub use report::report;

/// Blocks with more columns than this are reduced on a spanning tree (`tree.rs`), smaller
/// ones factored densely.
const DENSE_BLOCK: usize = 600;

/// Columns of a node in the virtual-motion vector.
struct Columns {
    start: Vec<usize>,
    rotates: Vec<bool>,
    n: usize,
    nodes: Vec<Node>,
    /// The index in `nodes` of each beam's first node (bodies come first, one node each).
    beam_base: Vec<usize>,
}

fn columns(model: &Model) -> Columns {
    let mut nodes = Vec::new();
    let mut start = Vec::new();
    let mut rotates = Vec::new();
    let mut beam_base = Vec::new();
    let mut n = 0;
    for (body, b) in model.bodies.iter().enumerate() {
        nodes.push(Node::Body { body });
        start.push(n);
        let r = b.kind == BodyKind::Rigid;
        rotates.push(r);
        n += if r { 6 } else { 3 };
    }
    for (beam, b) in model.beams.iter().enumerate() {
        beam_base.push(nodes.len());
        for node in 0..b.nodes.len() {
            nodes.push(Node::BeamNode { beam, node });
            start.push(n);
            rotates.push(true);
            n += 6;
        }
    }
    Columns {
        start,
        rotates,
        n,
        nodes,
        beam_base,
    }
}

impl Columns {
    fn of(&self, node: Node) -> usize {
        match node {
            Node::Body { body } => body,
            Node::BeamNode { beam, node } => self.beam_base[beam] + node,
        }
    }

    fn width(&self, k: usize) -> usize {
        if self.rotates[k] {
            6
        } else {
            3
        }
    }
}

fn node_position(model: &Model, node: Node) -> [f64; 3] {
    match node {
        Node::Body { body } => model.bodies[body].position,
        Node::BeamNode { beam, node } => model.beams[beam].nodes[node],
    }
}

/// A sparse row: (column, value) pairs, a column possibly repeated (the values add).
type Row = Vec<(usize, f64)>;

/// Rows of the linearised constraint equations, `dir . (relative translation)` or
/// `dir . (relative rotation)`, scaled so rotations are measured in lengths of `scale`.
struct Rows<'a> {
    model: &'a Model,
    cols: &'a Columns,
    scale: f64,
    rows: Vec<Row>,
}

impl Rows<'_> {
    /// Adds `sign * dir . (virtual displacement of the point p attached by a)`.
    fn translation(&self, row: &mut Row, a: &Attach, p: [f64; 3], dir: [f64; 3], sign: f64) {
        let nodes = attach_nodes(self.model, a);
        let w = 1.0 / nodes.len().max(1) as f64;
        for node in nodes {
            let k = self.cols.of(node);
            let s = self.cols.start[k];
            for i in 0..3 {
                row.push((s + i, sign * w * dir[i]));
            }
            if self.cols.rotates[k] {
                // d . (dtheta x r) = dtheta . (r x d)
                let r = sub(p, node_position(self.model, node));
                let c = cross(r, dir);
                for i in 0..3 {
                    row.push((s + 3 + i, sign * w * c[i] / self.scale));
                }
            }
        }
    }

    fn rotation(&self, row: &mut Row, a: &Attach, dir: [f64; 3], sign: f64) {
        let nodes = attach_nodes(self.model, a);
        let w = 1.0 / nodes.len().max(1) as f64;
        for node in nodes {
            let k = self.cols.of(node);
            if self.cols.rotates[k] {
                let s = self.cols.start[k];
                for i in 0..3 {
                    row.push((s + 3 + i, sign * w * dir[i]));
                }
            }
        }
    }

    fn lock_translation(&mut self, m: &[Marker; 2], dir: [f64; 3]) {
        let mut row = Row::new();
        self.translation(&mut row, &m[1].attach, m[1].position, dir, 1.0);
        self.translation(&mut row, &m[0].attach, m[0].position, dir, -1.0);
        self.rows.push(row);
    }

    fn lock_rotation(&mut self, m: &[Marker; 2], dir: [f64; 3]) {
        let mut row = Row::new();
        self.rotation(&mut row, &m[1].attach, dir, 1.0);
        self.rotation(&mut row, &m[0].attach, dir, -1.0);
        self.rows.push(row);
    }
}

/// Two unit vectors perpendicular to `n` and to each other.
fn perpendiculars(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let t = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let a = cross(n, t);
    let a = a.map(|x| x / norm(a));
    (a, cross(n, a))
}

const E: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// The constraint rows of one joint, in the order of its multipliers.
fn joint_rows(r: &mut Rows, j: &Joint) {
    match &j.kind {
        JointKind::Spherical => E.iter().for_each(|e| r.lock_translation(&j.markers, *e)),
        JointKind::Fixed => {
            E.iter().for_each(|e| r.lock_translation(&j.markers, *e));
            E.iter().for_each(|e| r.lock_rotation(&j.markers, *e));
        }
        JointKind::Revolute { axis, drive, .. } => {
            E.iter().for_each(|e| r.lock_translation(&j.markers, *e));
            let (a, b) = perpendiculars(*axis);
            r.lock_rotation(&j.markers, a);
            r.lock_rotation(&j.markers, b);
            if !matches!(drive, Drive::Free) {
                r.lock_rotation(&j.markers, *axis);
            }
        }
        JointKind::Prismatic { axis, drive, .. } => {
            let (a, b) = perpendiculars(*axis);
            r.lock_translation(&j.markers, a);
            r.lock_translation(&j.markers, b);
            E.iter().for_each(|e| r.lock_rotation(&j.markers, *e));
            if !matches!(drive, Drive::Free) {
                r.lock_translation(&j.markers, *axis);
            }
        }
        JointKind::Cylindrical { axis } => {
            let (a, b) = perpendiculars(*axis);
            r.lock_translation(&j.markers, a);
            r.lock_translation(&j.markers, b);
            r.lock_rotation(&j.markers, a);
            r.lock_rotation(&j.markers, b);
        }
        JointKind::Universal { axis_a, axis_b } => {
            E.iter().for_each(|e| r.lock_translation(&j.markers, *e));
            let c = cross(*axis_a, *axis_b);
            r.lock_rotation(&j.markers, c.map(|x| x / norm(c)));
        }
        JointKind::Distance { .. } => {
            let d = sub(j.markers[1].position, j.markers[0].position);
            let n = norm(d);
            r.lock_translation(&j.markers, d.map(|x| x / n));
        }
    }
}

fn locks_rotation(k: &JointKind) -> bool {
    !matches!(k, JointKind::Spherical | JointKind::Distance { .. })
}

/// Returns the joints whose equations are redundant but consistent (W0303) and how many of
/// their equations are surplus: the run drops that many.
pub fn check(model: &Model, sink: &mut Sink) -> (Vec<usize>, usize) {
    let cols = columns(model);
    // A joint that locks rotations needs something that rotates on at least one side.
    let mut bad = false;
    for j in &model.joints {
        if !locks_rotation(&j.kind) {
            continue;
        }
        let rotating = j.markers.iter().any(|m| match m.attach {
            Attach::Body { body } => model.bodies[body].kind == BodyKind::Rigid,
            Attach::BeamNode { .. } | Attach::BeamPoint { .. } => true,
            Attach::Ground { .. } => false,
        });
        let point_mass = j.markers.iter().any(|m| matches!(m.attach, Attach::Body { body } if model.bodies[body].kind == BodyKind::PointMass));
        if !rotating || point_mass {
            bad = true;
            sink.push(
                Diagnostic::error(Code::E0306, format!("{} joint `{}` locks rotations of a point mass", j.kind.name(), j.name))
                    .at(j.span, "declared here")
                    .hint("a point mass has no rotation: connect it with a `spherical` or `distance` joint, or make the body `rigid`"),
            );
        }
    }
    if bad {
        return (Vec::new(), 0);
    }
    connectivity(model, sink);
    let scale = length_scale(model);
    let mut r = Rows {
        model,
        cols: &cols,
        scale,
        rows: Vec::new(),
    };
    let mut owner = Vec::new();
    for (ji, j) in model.joints.iter().enumerate() {
        let before = r.rows.len();
        joint_rows(&mut r, j);
        owner.extend(std::iter::repeat_n(ji, r.rows.len() - before));
    }
    let redundant = if r.rows.is_empty() {
        (Vec::new(), 0)
    } else {
        redundancy(model, &r, &owner, sink)
    };
    if sink.has_errors() {
        return (Vec::new(), 0);
    }
    massless::check(model, &mut r, sink);
    redundant
}

/// The vertex of the ground in the joint graph, after every node's.
fn vertices(model: &Model, cols: &Columns, j: &Joint) -> Vec<usize> {
    let mut v: Vec<usize> = j
        .markers
        .iter()
        .flat_map(|m| match m.attach {
            Attach::Ground { .. } => vec![cols.nodes.len()],
            _ => attach_nodes(model, &m.attach)
                .into_iter()
                .map(|n| cols.of(n))
                .collect(),
        })
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// The joints that may take part in a constraint dependency, in blocks with disjoint columns
/// (`blocks.rs`): every joint but the bridges between two vertices.
fn loop_blocks(model: &Model, cols: &Columns) -> Vec<Vec<usize>> {
    let nv = cols.nodes.len() + 1;
    let verts: Vec<Vec<usize>> = model
        .joints
        .iter()
        .map(|j| vertices(model, cols, j))
        .collect();
    let (mut edges, mut edge_of) = (Vec::new(), vec![usize::MAX; verts.len()]);
    for (j, v) in verts.iter().enumerate() {
        if v.len() == 2 {
            edge_of[j] = edges.len();
        }
        // A joint on more than two vertices (a point between beam nodes) connects them all.
        edges.extend(v.windows(2).map(|w| (w[0], w[1])));
    }
    let bridge = blocks::bridges(nv, &edges);
    let mut sets = blocks::UnionFind::new(nv);
    let looped: Vec<usize> = (0..verts.len())
        .filter(|&j| edge_of[j] == usize::MAX || !bridge[edge_of[j]])
        .collect();
    for &j in &looped {
        for w in verts[j].windows(2) {
            sets.union(w[0], w[1]);
        }
    }
    let mut by_root: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    let mut order = Vec::new();
    for &j in &looped {
        let root = sets.find(verts[j][0]);
        let block = by_root.entry(root).or_default();
        if block.is_empty() {
            order.push(root);
        }
        block.push(j);
    }
    order
        .into_iter()
        .filter_map(|root| by_root.remove(&root))
        .collect()
}

/// A block's rows as a dense matrix over the columns they touch.
fn dense(rows: &[&Row]) -> DMatrix<f64> {
    let mut local = std::collections::HashMap::new();
    for row in rows {
        for &(c, _) in row.iter() {
            let next = local.len();
            local.entry(c).or_insert(next);
        }
    }
    let mut m = DMatrix::zeros(rows.len(), local.len());
    for (i, row) in rows.iter().enumerate() {
        for &(c, v) in row.iter() {
            m[(i, local[&c])] += v;
        }
    }
    m
}

fn length_scale(model: &Model) -> f64 {
    let mut s: f64 = 0.0;
    for b in &model.bodies {
        s = s.max(norm(b.position));
        for m in &b.markers {
            s = s.max(norm(m.1));
        }
    }
    for b in &model.beams {
        s = s.max(b.length);
    }
    if s > 0.0 {
        s
    } else {
        1.0
    }
}

/// Union-find over grounds (one node), bodies and beams.
fn connectivity(model: &Model, sink: &mut Sink) {
    let nb = model.bodies.len();
    let n = nb + model.beams.len() + 1;
    let ground = n - 1;
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], x: usize) -> usize {
        let mut r = x;
        while p[r] != r {
            r = p[r];
        }
        let mut y = x;
        while p[y] != r {
            let next = p[y];
            p[y] = r;
            y = next;
        }
        r
    }
    let id = |a: &Attach| match *a {
        Attach::Ground { .. } => ground,
        Attach::Body { body } => body,
        Attach::BeamNode { beam, .. } | Attach::BeamPoint { beam, .. } => nb + beam,
    };
    let pairs = model
        .joints
        .iter()
        .map(|j| (&j.markers[0], &j.markers[1]))
        .chain(model.springs.iter().map(|s| (&s.markers[0], &s.markers[1])));
    for (a, b) in pairs {
        let (x, y) = (
            find(&mut parent, id(&a.attach)),
            find(&mut parent, id(&b.attach)),
        );
        parent[x] = y;
    }
    let g = find(&mut parent, ground);
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for k in 0..n - 1 {
        let r = find(&mut parent, k);
        if r != g {
            groups.entry(r).or_default().push(k);
        }
    }
    for members in groups.values() {
        let name = |k: usize| {
            if k < nb {
                model.bodies[k].name.clone()
            } else {
                model.beams[k - nb].name.clone()
            }
        };
        let span = |k: usize| {
            if k < nb {
                model.bodies[k].span
            } else {
                model.beams[k - nb].span
            }
        };
        let rotates = members
            .iter()
            .any(|&k| k >= nb || model.bodies[k].kind == BodyKind::Rigid);
        let free = if rotates {
            "translations along x, y, z and rotations about x, y, z"
        } else {
            "translations along x, y, z"
        };
        let others = match members.len() {
            1 => String::new(),
            2 => format!(" (with `{}`)", name(members[1])),
            k => format!(" (with {} other bodies)", k - 1),
        };
        sink.push(
            Diagnostic::warning(Code::W0301, format!("`{}`{others} has no path to ground: its {free} are free", name(members[0])))
                .at(span(members[0]), "floats freely")
                .hint("connect it to a ground with a joint or a spring; a body meant to fly free (a free-flight test) may ignore this"),
        );
    }
}

/// Dependent constraint equations, the null space of `J J^T` block by block: W0303 when no
/// drive takes part (joints' equations that hold at the start and imply each other: the run
/// drops the surplus), E0307 when one does (a prescribed motion that the other joints fix or
/// couple). Returns the joints of consistent dependencies.
fn redundancy(model: &Model, r: &Rows, owner: &[usize], sink: &mut Sink) -> (Vec<usize>, usize) {
    let m = r.rows.len();
    let mut first = vec![usize::MAX; model.joints.len()];
    for (i, &o) in owner.iter().enumerate().rev() {
        first[o] = i;
    }
    let (mut involved, mut nulls) = (vec![0.0f64; model.joints.len()], 0);
    let rows_of = |j: usize| first[j]..(first[j]..m).find(|&i| owner[i] != j).unwrap_or(m);
    // A drive's row is its joint's last (see `joint_rows`).
    let driven = |i: usize| {
        let j = owner[i];
        let last = rows_of(j).end - 1;
        i == last
            && matches!(&model.joints[j].kind,
                JointKind::Revolute { drive, .. } | JointKind::Prismatic { drive, .. }
                    if !matches!(drive, Drive::Free))
    };
    let (mut drive_involved, mut large) = (false, false);
    for block in loop_blocks(model, r.cols) {
        let rows: Vec<usize> = block.iter().flat_map(|&j| rows_of(j)).collect();
        let mut nodes: Vec<usize> = block
            .iter()
            .flat_map(|&j| vertices(model, r.cols, &model.joints[j]))
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        let width: usize = nodes
            .iter()
            .filter(|&&k| k < r.cols.nodes.len())
            .map(|&k| r.cols.width(k))
            .sum();
        if width > DENSE_BLOCK {
            for dep in tree::dependencies(model, r, &block, &rows_of) {
                nulls += 1;
                large = true;
                let top = dep.iter().fold(0.0f64, |a, (_, v)| a.max(v.abs()));
                for (i, v) in dep {
                    involved[owner[i]] = involved[owner[i]].max(v.abs());
                    drive_involved |= driven(i) && v.abs() > 1e-6 * top;
                }
            }
            continue;
        }
        let jb = dense(&rows.iter().map(|&i| &r.rows[i]).collect::<Vec<_>>());
        let eig = SymmetricEigen::new(&jb * jb.transpose());
        let top = eig.eigenvalues.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let tol = 1e-10 * top.max(1e-30) * rows.len() as f64;
        for c in (0..rows.len()).filter(|&c| eig.eigenvalues[c].abs() <= tol) {
            nulls += 1;
            for (k, &i) in rows.iter().enumerate() {
                let v = eig.eigenvectors[(k, c)].abs();
                involved[owner[i]] = involved[owner[i]].max(v);
                drive_involved |= driven(i) && v > 1e-6;
            }
        }
    }
    if nulls == 0 {
        return (Vec::new(), 0);
    }
    let names: Vec<usize> = (0..model.joints.len())
        .filter(|&k| involved[k] > 1e-6)
        .collect();
    let list = names
        .iter()
        .map(|&k| format!("`{}`", model.joints[k].name))
        .collect::<Vec<_>>()
        .join(", ");
    let plural = if nulls == 1 { "" } else { "s" };
    let refuse = drive_involved || large;
    let mut d = if large && !drive_involved {
        Diagnostic::error(
            Code::E0307,
            format!("redundant constraints: {list} lock the same motion ({nulls} equation{plural} too many), in a loop too large to drop equations from"),
        )
    } else if drive_involved {
        Diagnostic::error(
            Code::E0307,
            format!("redundant constraints: {list} lock the same motion, a drive among them ({nulls} equation{plural} too many)"),
        )
    } else {
        Diagnostic::warning(
            Code::W0303,
            format!("redundant constraints: {list} lock the same motion ({nulls} equation{plural} too many); the run drops {nulls} of their equations, and their forces are one split among many"),
        )
    };
    for &k in &names {
        d = d.at(
            model.joints[k].span,
            format!("{} joint", model.joints[k].kind.name()),
        );
    }
    let rank = m - nulls;
    sink.push(if large && !drive_involved {
        d.hint(format!(
            "the constraint Jacobian has rank {rank} for {m} equations at the initial configuration; a loop of over {DENSE_BLOCK} unknowns is not reduced at run time: free one of these joints (a spherical instead of a revolute, a cylindrical instead of a prismatic)"
        ))
    } else if drive_involved {
        d.hint(format!(
            "the constraint Jacobian has rank {rank} for {m} equations at the initial configuration, and a drive prescribes a motion the other joints already fix: drive a free motion, or free one of these joints (a spherical instead of a revolute, a cylindrical instead of a prismatic)"
        ))
    } else {
        d.hint(format!(
            "the constraint Jacobian has rank {rank} for {m} equations at the initial configuration; the joint forces reported are the minimum-norm split (the mechanism cannot tell how the joints share the load); to have one split, free one of these joints (a spherical instead of a revolute, a cylindrical instead of a prismatic)"
        ))
    });
    if refuse {
        (Vec::new(), 0)
    } else {
        (names, nulls)
    }
}
