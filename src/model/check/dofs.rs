//! Numbering of the unknowns.
//!
//! Nodes (bodies and beam nodes) are ordered by reverse Cuthill-McKee over the graph of what
//! couples them (joints, springs, beam elements), which keeps the iteration matrix's bandwidth
//! and fill low. Invariant: every joint's extra unknown and multipliers come right after the
//! last node it couples, so eliminating a multiplier meets a non-zero pivot (THEORY §6) and the
//! factorization needs no pivoting.
//!
//! Contract: reads a complete model; must not know the syntax, the scopes or the runtime.

use crate::model::{Attach, BodyKind, Marker, Model};
use serde::Serialize;
use std::collections::VecDeque;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Unknown {
    /// Displacement of a body's reference point along inertial axis 0, 1 or 2.
    Translation { body: usize, axis: usize },
    /// Rotation of a rigid body (a component of its rotation parameters).
    Rotation { body: usize, axis: usize },
    NodeTranslation {
        beam: usize,
        node: usize,
        axis: usize,
    },
    NodeRotation {
        beam: usize,
        node: usize,
        axis: usize,
    },
    /// The relative angle of a revolute joint.
    JointAngle { joint: usize },
    /// Row `row` of a joint's multipliers.
    Multiplier { joint: usize, row: usize },
}

/// A node of the topology: a body or a beam node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Node {
    Body { body: usize },
    BeamNode { beam: usize, node: usize },
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct DofMap {
    pub unknowns: Vec<Unknown>,
    /// Nodes in the order their unknowns appear.
    pub order: Vec<Node>,
    /// First unknown of each body (3 for a point mass, 6 for a rigid body, in a row).
    pub body_start: Vec<usize>,
    /// First unknown of each beam node (6 in a row).
    pub node_start: Vec<Vec<usize>>,
    /// First multiplier of each joint.
    pub joint_start: Vec<usize>,
    /// The extra unknown (revolute angle) of each joint, if any.
    pub joint_extra: Vec<Option<usize>>,
    /// Largest distance from the diagonal of a coupling in the iteration matrix.
    pub bandwidth: usize,
}

fn node_index(model: &Model) -> (Vec<Node>, impl Fn(Node) -> usize + '_) {
    let mut nodes: Vec<Node> = (0..model.bodies.len())
        .map(|body| Node::Body { body })
        .collect();
    let mut beam_first = Vec::new();
    for (beam, b) in model.beams.iter().enumerate() {
        beam_first.push(nodes.len());
        nodes.extend((0..b.nodes.len()).map(|node| Node::BeamNode { beam, node }));
    }
    let index = move |n: Node| match n {
        Node::Body { body } => body,
        Node::BeamNode { beam, node } => beam_first[beam] + node,
    };
    (nodes, index)
}

/// The nodes an attachment moves with (a point between beam nodes moves with its element's).
pub fn attach_nodes(model: &Model, a: &Attach) -> Vec<Node> {
    match *a {
        Attach::Ground { .. } => Vec::new(),
        Attach::Body { body } => vec![Node::Body { body }],
        Attach::BeamNode { beam, node } => vec![Node::BeamNode { beam, node }],
        Attach::BeamPoint { beam, s } => {
            // Every node of the element holding the point.
            let b = &model.beams[beam];
            let le = b.length / b.elements as f64;
            let e = ((s / le).floor().max(0.0) as usize).min(b.elements - 1);
            let first = e * (b.order - 1);
            (first..first + b.order)
                .map(|node| Node::BeamNode { beam, node })
                .collect()
        }
    }
}

/// What couples nodes: each joint's and spring's nodes, each beam element's; the joints'
/// groups first, one per joint.
fn coupling_groups(model: &Model, index: &impl Fn(Node) -> usize) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let nodes_of = |markers: &[Marker; 2]| -> Vec<usize> {
        markers
            .iter()
            .flat_map(|m| attach_nodes(model, &m.attach))
            .map(index)
            .collect()
    };
    for j in &model.joints {
        groups.push(nodes_of(&j.markers));
    }
    for s in &model.springs {
        groups.push(nodes_of(&s.markers));
    }
    for (bi, b) in model.beams.iter().enumerate() {
        for e in 0..b.elements {
            let first = e * (b.order - 1);
            groups.push(
                (first..first + b.order)
                    .map(|k| index(Node::BeamNode { beam: bi, node: k }))
                    .collect(),
            );
        }
    }
    groups
}

impl DofMap {
    pub fn new(model: &Model) -> DofMap {
        let (nodes, index) = node_index(model);
        let n = nodes.len();
        let groups = coupling_groups(model, &index);
        let joint_nodes = &groups[..model.joints.len()];
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
        for g in &groups {
            for &a in g {
                for &b in g {
                    if a != b && !adj[a].contains(&b) {
                        adj[a].push(b);
                    }
                }
            }
        }
        let perm = reverse_cuthill_mckee(&adj);
        let mut rank = vec![0; n];
        for (r, &v) in perm.iter().enumerate() {
            rank[v] = r;
        }
        // Joints by the position of their last node (joints to ground only: that node).
        let mut after: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (ji, g) in joint_nodes.iter().enumerate() {
            if let Some(&last) = g.iter().max_by_key(|&&v| rank[v]) {
                after[last].push(ji);
            }
        }
        let mut map = DofMap::number(model, &nodes, &perm, &after);
        map.bandwidth = map.bandwidth_of(model, &nodes, &groups);
        map
    }

    /// Numbers the unknowns node by node in the order `perm`, each joint's extra unknown and
    /// multipliers right after the node it comes `after`.
    fn number(model: &Model, nodes: &[Node], perm: &[usize], after: &[Vec<usize>]) -> DofMap {
        let mut map = DofMap {
            body_start: vec![0; model.bodies.len()],
            node_start: model.beams.iter().map(|b| vec![0; b.nodes.len()]).collect(),
            joint_start: vec![0; model.joints.len()],
            joint_extra: vec![None; model.joints.len()],
            ..Default::default()
        };
        for &v in perm {
            let node = nodes[v];
            map.order.push(node);
            match node {
                Node::Body { body } => {
                    map.body_start[body] = map.unknowns.len();
                    map.unknowns
                        .extend((0..3).map(|axis| Unknown::Translation { body, axis }));
                    if model.bodies[body].kind == BodyKind::Rigid {
                        map.unknowns
                            .extend((0..3).map(|axis| Unknown::Rotation { body, axis }));
                    }
                }
                Node::BeamNode { beam, node } => {
                    map.node_start[beam][node] = map.unknowns.len();
                    map.unknowns
                        .extend((0..3).map(|axis| Unknown::NodeTranslation { beam, node, axis }));
                    map.unknowns
                        .extend((0..3).map(|axis| Unknown::NodeRotation { beam, node, axis }));
                }
            }
            for &ji in &after[v] {
                let j = &model.joints[ji];
                if j.kind.extra_unknowns() > 0 {
                    map.joint_extra[ji] = Some(map.unknowns.len());
                    map.unknowns.push(Unknown::JointAngle { joint: ji });
                }
                map.joint_start[ji] = map.unknowns.len();
                map.unknowns.extend(
                    (0..j.kind.multipliers()).map(|row| Unknown::Multiplier { joint: ji, row }),
                );
            }
        }
        map
    }

    /// The bandwidth over every coupling.
    fn bandwidth_of(&self, model: &Model, nodes: &[Node], groups: &[Vec<usize>]) -> usize {
        let dofs_of = |v: usize| -> (usize, usize) {
            match nodes[v] {
                Node::Body { body } => {
                    let s = self.body_start[body];
                    (
                        s,
                        s + if model.bodies[body].kind == BodyKind::Rigid {
                            5
                        } else {
                            2
                        },
                    )
                }
                Node::BeamNode { beam, node } => {
                    let s = self.node_start[beam][node];
                    (s, s + 5)
                }
            }
        };
        let mut bw = 0;
        for v in 0..nodes.len() {
            let (lo, hi) = dofs_of(v);
            bw = bw.max(hi - lo);
        }
        for (gi, g) in groups.iter().enumerate() {
            let mut lo = usize::MAX;
            let mut hi = 0;
            for &v in g {
                let (a, b) = dofs_of(v);
                lo = lo.min(a);
                hi = hi.max(b);
            }
            if gi < model.joints.len() {
                let j = &model.joints[gi];
                let s = self.joint_start[gi];
                let last = s + j.kind.multipliers().max(1) - 1;
                lo = lo.min(self.joint_extra[gi].unwrap_or(s)).min(s);
                hi = hi.max(last);
            }
            if lo <= hi {
                bw = bw.max(hi - lo);
            }
        }
        bw
    }

    pub fn len(&self) -> usize {
        self.unknowns.len()
    }

    pub fn is_empty(&self) -> bool {
        self.unknowns.is_empty()
    }

    pub fn multipliers(&self) -> usize {
        self.unknowns
            .iter()
            .filter(|u| matches!(u, Unknown::Multiplier { .. }))
            .count()
    }

    pub fn extras(&self) -> usize {
        self.unknowns
            .iter()
            .filter(|u| matches!(u, Unknown::JointAngle { .. }))
            .count()
    }
}

/// Reverse Cuthill-McKee: breadth-first from a low-degree node of each connected part,
/// neighbours by increasing degree, then reversed.
pub fn reverse_cuthill_mckee(adj: &[Vec<usize>]) -> Vec<usize> {
    let n = adj.len();
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut by_degree: Vec<usize> = (0..n).collect();
    by_degree.sort_by_key(|&v| (adj[v].len(), v));
    for &start in &by_degree {
        if seen[start] {
            continue;
        }
        // A pseudo-peripheral start: the last node reached by a BFS from `start`.
        let root = farthest(adj, start);
        let mut queue = VecDeque::from([root]);
        seen[root] = true;
        while let Some(v) = queue.pop_front() {
            order.push(v);
            let mut next: Vec<usize> = adj[v].iter().copied().filter(|&w| !seen[w]).collect();
            next.sort_by_key(|&w| (adj[w].len(), w));
            for w in next {
                seen[w] = true;
                queue.push_back(w);
            }
        }
    }
    order.reverse();
    order
}

fn farthest(adj: &[Vec<usize>], start: usize) -> usize {
    let mut dist = vec![usize::MAX; adj.len()];
    dist[start] = 0;
    let mut queue = VecDeque::from([start]);
    let mut last = start;
    while let Some(v) = queue.pop_front() {
        last = v;
        let mut next: Vec<usize> = adj[v]
            .iter()
            .copied()
            .filter(|&w| dist[w] == usize::MAX)
            .collect();
        next.sort_by_key(|&w| (adj[w].len(), w));
        for w in next {
            dist[w] = dist[v] + 1;
            queue.push_back(w);
        }
    }
    last
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bandwidth(adj: &[Vec<usize>], perm: &[usize]) -> usize {
        let mut rank = vec![0; perm.len()];
        for (r, &v) in perm.iter().enumerate() {
            rank[v] = r;
        }
        let mut bw = 0;
        for (v, ns) in adj.iter().enumerate() {
            for &w in ns {
                bw = bw.max(rank[v].abs_diff(rank[w]));
            }
        }
        bw
    }

    #[test]
    fn rcm_recovers_a_chain_from_a_shuffled_numbering() {
        // A chain 0-1-2-...-19 numbered in a scrambled order.
        let n = 20;
        let label: Vec<usize> = (0..n).map(|i| (i * 7) % n).collect();
        let mut adj = vec![Vec::new(); n];
        for i in 0..n - 1 {
            adj[label[i]].push(label[i + 1]);
            adj[label[i + 1]].push(label[i]);
        }
        let identity: Vec<usize> = (0..n).collect();
        assert!(bandwidth(&adj, &identity) > 5);
        let perm = reverse_cuthill_mckee(&adj);
        assert_eq!(bandwidth(&adj, &perm), 1);
        let mut sorted = perm.clone();
        sorted.sort();
        assert_eq!(sorted, identity);
    }

    #[test]
    fn rcm_keeps_a_star_within_its_degree_and_covers_disconnected_parts() {
        let mut adj = vec![Vec::new(); 7];
        for k in 1..5 {
            adj[0].push(k);
            adj[k].push(0);
        }
        adj[5].push(6);
        adj[6].push(5);
        let perm = reverse_cuthill_mckee(&adj);
        assert_eq!(perm.len(), 7);
        assert!(bandwidth(&adj, &perm) <= 4);
    }
}
