//! The 3-D view as a glTF 2.0 binary (`--gltf OUT.glb`): one node per anchor, animated by
//! its sampled translation and rotation, its shapes as meshes under it; links (beam segments,
//! springs, distance joints) and load arrows as nodes of their own, animated by translation,
//! rotation and scale. Blender and any glTF viewer open it.
//!
//! Written here with serde_json: the document is a few arrays of plain objects, and the
//! layout (chunks, alignment, accessor bounds) is checked by `tests/view.rs` with the `gltf`
//! crate's reader and validator.

use crate::runtime::rotation::V3;
use crate::runtime::scene::{Frames, Look, Scene};
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::io::{self, Write};

/// The binary buffer and the JSON arrays that point into it.
#[derive(Default)]
struct Doc {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    nodes: Vec<Value>,
}

impl Doc {
    /// Appends floats as an accessor of `kind` (`VEC3`, `SCALAR`, ...) with their bounds.
    fn floats(&mut self, v: &[f32], kind: &str, width: usize, target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        for x in v {
            self.bin.extend_from_slice(&x.to_le_bytes());
        }
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": 4 * v.len()});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.views.push(view);
        let count = v.len() / width;
        let (mut lo, mut hi) = (vec![f32::INFINITY; width], vec![f32::NEG_INFINITY; width]);
        for row in v.chunks(width) {
            for k in 0..width {
                lo[k] = lo[k].min(row[k]);
                hi[k] = hi[k].max(row[k]);
            }
        }
        self.accessors.push(json!({
            "bufferView": self.views.len() - 1, "componentType": 5126, "count": count,
            "type": kind, "min": lo, "max": hi,
        }));
        self.accessors.len() - 1
    }

    fn material(&mut self, color: u32) -> usize {
        let c = |s: u32| ((color >> s) & 0xff) as f64 / 255.0;
        // glTF colours are linear; the scene's are sRGB.
        let lin = |x: f64| {
            if x <= 0.04045 {
                x / 12.92
            } else {
                ((x + 0.055) / 1.055).powf(2.4)
            }
        };
        self.materials.push(json!({
            "pbrMetallicRoughness": {
                "baseColorFactor": [lin(c(16)), lin(c(8)), lin(c(0)), 1.0],
                "metallicFactor": 0.1, "roughnessFactor": 0.6,
            }
        }));
        self.materials.len() - 1
    }

    /// A mesh of triangles (positions and normals) or lines (`mode` 1).
    fn mesh(
        &mut self,
        name: &str,
        pos: &[f32],
        normals: Option<&[f32]>,
        color: u32,
        mode: u32,
    ) -> usize {
        let p = self.floats(pos, "VEC3", 3, Some(34962));
        let mut attributes = json!({"POSITION": p});
        if let Some(n) = normals {
            attributes["NORMAL"] = json!(self.floats(n, "VEC3", 3, Some(34962)));
        }
        let material = self.material(color);
        self.meshes.push(json!({
            "name": name,
            "primitives": [{"attributes": attributes, "material": material, "mode": mode}],
        }));
        self.meshes.len() - 1
    }
}

/// Triangles of a look, in its anchor's axes (or, for links and arrows, along a unit +y).
fn triangles(look: &Look) -> Option<(Vec<f32>, Vec<f32>)> {
    let (mut p, mut n) = (Vec::new(), Vec::new());
    let mut tri = |a: V3, b: V3, c: V3, na: V3, nb: V3, nc: V3| {
        for (x, m) in [(a, na), (b, nb), (c, nc)] {
            p.extend(x.iter().map(|v| *v as f32));
            n.extend(m.iter().map(|v| *v as f32));
        }
    };
    match look {
        Look::Box { half, center } => {
            let c = V3::from(*center);
            for axis in 0..3 {
                for sign in [-1.0, 1.0] {
                    let mut nrm = V3::zeros();
                    nrm[axis] = sign;
                    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                    let corner = |su: f64, sv: f64| {
                        let mut x = nrm * half[axis];
                        x[u] = su * half[u];
                        x[v] = sv * half[v];
                        c + x
                    };
                    let (a, b, cc, d) = (
                        corner(-1.0, -1.0),
                        corner(1.0, -1.0),
                        corner(1.0, 1.0),
                        corner(-1.0, 1.0),
                    );
                    if sign > 0.0 {
                        tri(a, b, cc, nrm, nrm, nrm);
                        tri(a, cc, d, nrm, nrm, nrm);
                    } else {
                        tri(a, cc, b, nrm, nrm, nrm);
                        tri(a, d, cc, nrm, nrm, nrm);
                    }
                }
            }
        }
        Look::Sphere { radius, center } => {
            let (rings, segs) = (12, 24);
            let at = |i: usize, j: usize| {
                let th = PI * i as f64 / rings as f64;
                let ph = 2.0 * PI * j as f64 / segs as f64;
                V3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin())
            };
            let c = V3::from(*center);
            for i in 0..rings {
                for j in 0..segs {
                    let (a, b, cc, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    tri(c + a * *radius, c + d * *radius, c + cc * *radius, a, d, cc);
                    tri(c + a * *radius, c + cc * *radius, c + b * *radius, a, cc, b);
                }
            }
        }
        Look::Cylinder {
            radius,
            length,
            center,
        } => {
            // Along the anchor's axis 1.
            cylinder(
                &mut tri,
                *radius,
                -0.5 * length,
                0.5 * length,
                0,
                V3::from(*center),
            );
        }
        Look::Link { radius, coils, .. } if *coils > 0 => helix(&mut tri, *radius, *coils),
        Look::Link { radius, .. } => cylinder(&mut tri, *radius, -0.5, 0.5, 1, V3::zeros()),
        Look::Arrow { .. } => {
            // A unit arrow along +y: shaft to 0.75, head to 1.
            cylinder(&mut tri, 0.02, 0.0, 0.75, 1, V3::zeros());
            cone(&mut tri, 0.08, 0.75, 1.0);
        }
        Look::Triad { .. } | Look::Grid { .. } => return None,
    }
    Some((p, n))
}

type Tri<'a> = dyn FnMut(V3, V3, V3, V3, V3, V3) + 'a;

/// A closed cylinder along axis `along` from `a` to `b`.
fn cylinder(tri: &mut Tri, r: f64, a: f64, b: f64, along: usize, c: V3) {
    let segs = 20;
    let (u, v) = ((along + 1) % 3, (along + 2) % 3);
    let ring = |j: usize| {
        let ph = 2.0 * PI * j as f64 / segs as f64;
        let mut x = V3::zeros();
        x[u] = ph.cos();
        x[v] = ph.sin();
        x
    };
    let mut axis = V3::zeros();
    axis[along] = 1.0;
    for j in 0..segs {
        let (p, q) = (ring(j), ring(j + 1));
        let (pa, pb, qa, qb) = (
            c + p * r + axis * a,
            c + p * r + axis * b,
            c + q * r + axis * a,
            c + q * r + axis * b,
        );
        tri(pa, qb, pb, p, q, p);
        tri(pa, qa, qb, p, q, q);
        tri(c + axis * b, pb, qb, axis, axis, axis);
        tri(c + axis * a, qa, pa, -axis, -axis, -axis);
    }
}

/// A spring's helix of radius `r` and `turns` turns from y = -1/2 to 1/2 (the link's unit
/// length, scaled along y by its animation), its wire `r / 6` thick: as the HTML view draws it.
fn helix(tri: &mut Tri, r: f64, turns: u32) {
    let (along, around) = (24 * turns as usize, 6);
    let wire = r / 6.0;
    let w = 2.0 * PI * turns as f64;
    // The point of the wire's surface at step i along the helix, angle k around it, and its
    // normal: the wire's centre line, its tangent, and a frame normal to the tangent.
    let at = |i: usize, k: usize| {
        let u = i as f64 / along as f64;
        let a = w * u;
        let c = V3::new(r * a.cos(), u - 0.5, r * a.sin());
        let t = V3::new(-r * w * a.sin(), 1.0, r * w * a.cos()).normalize();
        let inward = V3::new(-a.cos(), 0.0, -a.sin());
        let b = t.cross(&inward);
        let ph = 2.0 * PI * k as f64 / around as f64;
        let d = inward * ph.cos() + b * ph.sin();
        (c + d * wire, d)
    };
    for i in 0..along {
        for k in 0..around {
            let (p, np) = at(i, k);
            let (q, nq) = at(i + 1, k);
            let (s, ns) = at(i + 1, k + 1);
            let (o, no) = at(i, k + 1);
            tri(p, s, q, np, ns, nq);
            tri(p, o, s, np, no, ns);
        }
    }
}

/// A cone along +y from `a` (radius `r`) to its tip at `b`.
fn cone(tri: &mut Tri, r: f64, a: f64, b: f64) {
    let segs = 20;
    let y = V3::y();
    for j in 0..segs {
        let (p0, p1) = (
            2.0 * PI * j as f64 / segs as f64,
            2.0 * PI * (j + 1) as f64 / segs as f64,
        );
        let (p, q) = (
            V3::new(p0.cos(), 0.0, p0.sin()),
            V3::new(p1.cos(), 0.0, p1.sin()),
        );
        let tip = y * b;
        tri(p * r + y * a, tip, q * r + y * a, p, y, q);
        tri(y * a, p * r + y * a, q * r + y * a, -y, -y, -y);
    }
}

/// Line segments of a triad (three meshes, red, green, blue) or a grid.
fn lines(look: &Look) -> Vec<(Vec<f32>, u32)> {
    match look {
        Look::Triad { size } => (0..3)
            .map(|k| {
                let mut e = [0.0f32; 3];
                e[k] = *size as f32;
                (
                    vec![0.0, 0.0, 0.0, e[0], e[1], e[2]],
                    [0xff0000, 0x00a000, 0x0000ff][k],
                )
            })
            .collect(),
        Look::Grid { size, normal } => {
            let nrm = V3::from(*normal);
            let helper = if nrm.x.abs() < 0.9 { V3::x() } else { V3::y() };
            let u = nrm.cross(&helper).normalize();
            let v = nrm.cross(&u);
            let mut p = Vec::new();
            let h = 0.5 * size;
            for k in 0..=20 {
                let s = -h + size * k as f64 / 20.0;
                for (a, b) in [
                    (u * s - v * h, u * s + v * h),
                    (v * s - u * h, v * s + u * h),
                ] {
                    p.extend(a.iter().chain(b.iter()).map(|x| *x as f32));
                }
            }
            vec![(p, 0xb0b6bf)]
        }
        _ => Vec::new(),
    }
}

/// An animated node: its index, translations, rotations and (links, arrows) scales.
type Animated = (usize, Vec<f32>, Vec<f32>, Option<Vec<f32>>);

/// Writes the scene and its sampled motion as a GLB file.
pub fn write_glb(
    out: &mut dyn Write,
    title: &str,
    scene: &Scene,
    frames: &Frames,
) -> io::Result<()> {
    let mut d = Doc::default();
    let na = scene.anchors.len();
    let nf = frames.t.len();
    let mut roots = Vec::new();
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); na];
    // Animated nodes: (node, translations, rotations, scales).
    let mut animated: Vec<Animated> = Vec::new();
    let pose = |k: usize, a: usize| {
        let p = &frames.positions[3 * (k * na + a)..3 * (k * na + a) + 3];
        let q = &frames.rotations[4 * (k * na + a)..4 * (k * na + a) + 4];
        (
            V3::new(p[0] as f64, p[1] as f64, p[2] as f64),
            [q[0], q[1], q[2], q[3]],
        )
    };
    for s in &scene.shapes {
        if let Some((p, n)) = triangles(&s.look) {
            let mesh = d.mesh(&s.name, &p, Some(&n), s.color, 4);
            match s.look {
                Look::Link { to, .. } => {
                    let (mut t, mut r, mut sc) = (Vec::new(), Vec::new(), Vec::new());
                    for k in 0..nf {
                        let (a, _) = pose(k, s.anchor);
                        let (b, _) = pose(k, to);
                        let dir = b - a;
                        let len = dir.norm().max(1e-9);
                        t.extend((0.5 * (a + b)).iter().map(|x| *x as f32));
                        r.extend(turn_y_to(dir / len));
                        sc.extend([1.0, len as f32, 1.0]);
                    }
                    d.nodes.push(json!({"name": s.name, "mesh": mesh}));
                    roots.push(d.nodes.len() - 1);
                    animated.push((d.nodes.len() - 1, t, r, Some(sc)));
                }
                Look::Arrow { load, scale } => {
                    let nl = scene.loads.len();
                    let top = (0..nf)
                        .map(|k| {
                            let v = &frames.loads[3 * (k * nl + load)..3 * (k * nl + load) + 3];
                            V3::new(v[0] as f64, v[1] as f64, v[2] as f64).norm()
                        })
                        .fold(0.0, f64::max);
                    let (mut t, mut r, mut sc) = (Vec::new(), Vec::new(), Vec::new());
                    for k in 0..nf {
                        let (a, _) = pose(k, s.anchor);
                        let v = &frames.loads[3 * (k * nl + load)..3 * (k * nl + load) + 3];
                        let v = V3::new(v[0] as f64, v[1] as f64, v[2] as f64);
                        let m = v.norm();
                        let len = if top > 0.0 { scale * m / top } else { 0.0 };
                        t.extend(a.iter().map(|x| *x as f32));
                        r.extend(turn_y_to(if m > 0.0 { v / m } else { V3::y() }));
                        sc.extend([len as f32; 3]);
                    }
                    d.nodes.push(json!({"name": s.name, "mesh": mesh}));
                    roots.push(d.nodes.len() - 1);
                    animated.push((d.nodes.len() - 1, t, r, Some(sc)));
                }
                _ => {
                    d.nodes.push(json!({"name": s.name, "mesh": mesh}));
                    children[s.anchor].push(d.nodes.len() - 1);
                }
            }
        }
        for (p, color) in lines(&s.look) {
            let mesh = d.mesh(&s.name, &p, None, color, 1);
            d.nodes.push(json!({"name": s.name, "mesh": mesh}));
            children[s.anchor].push(d.nodes.len() - 1);
        }
    }
    for (a, kids) in children.into_iter().enumerate() {
        if kids.is_empty() {
            continue;
        }
        let (x, q) = pose(0, a);
        d.nodes.push(json!({
            "name": format!("anchor {a}"), "children": kids,
            "translation": [x.x as f32, x.y as f32, x.z as f32], "rotation": q,
        }));
        roots.push(d.nodes.len() - 1);
        let mut t = Vec::with_capacity(3 * nf);
        let mut r = Vec::with_capacity(4 * nf);
        for k in 0..nf {
            let (x, q) = pose(k, a);
            t.extend(x.iter().map(|v| *v as f32));
            r.extend(q);
        }
        animated.push((d.nodes.len() - 1, t, r, None));
    }
    let animations = animations(&mut d, frames, animated);
    while d.bin.len() % 4 != 0 {
        d.bin.push(0);
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": concat!("mbd ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"name": title, "nodes": roots}],
        "nodes": d.nodes, "meshes": d.meshes, "materials": d.materials,
        "accessors": d.accessors, "bufferViews": d.views,
        "buffers": [{"byteLength": d.bin.len()}],
    });
    if !animations.is_empty() {
        doc["animations"] = json!(animations);
    }
    glb(out, doc.to_string().into_bytes(), &d.bin)
}

/// The GLB container: header, JSON chunk (padded with spaces), binary chunk.
fn glb(out: &mut dyn Write, mut text: Vec<u8>, bin: &[u8]) -> io::Result<()> {
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&(total as u32).to_le_bytes())?;
    out.write_all(&(text.len() as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(&text)?;
    out.write_all(&(bin.len() as u32).to_le_bytes())?;
    out.write_all(b"BIN\0")?;
    out.write_all(bin)
}

/// One animation of every animated node, sampled at the frames' times (from the first).
fn animations(d: &mut Doc, frames: &Frames, animated: Vec<Animated>) -> Vec<Value> {
    let nf = frames.t.len();
    let mut animations = Vec::new();
    if nf > 1 {
        let times: Vec<f32> = frames.t.iter().map(|t| (t - frames.t[0]) as f32).collect();
        let input = d.floats(&times, "SCALAR", 1, None);
        let (mut channels, mut samplers) = (Vec::new(), Vec::new());
        for (node, t, r, s) in animated {
            let mut add = |values: &[f32], kind: &str, width: usize, path: &str, d: &mut Doc| {
                let output = d.floats(values, kind, width, None);
                samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
                channels.push(
                    json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": path}}),
                );
            };
            add(&t, "VEC3", 3, "translation", d);
            add(&r, "VEC4", 4, "rotation", d);
            if let Some(s) = s {
                add(&s, "VEC3", 3, "scale", d);
            }
        }
        animations.push(json!({"name": "run", "channels": channels, "samplers": samplers}));
    }
    animations
}

/// The quaternion `(x, y, z, w)` turning +y onto the unit vector `u`.
fn turn_y_to(u: V3) -> [f32; 4] {
    let y = V3::y();
    let c = y.dot(&u);
    if c < -1.0 + 1e-12 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let axis = y.cross(&u);
    let w = 1.0 + c;
    let n = (axis.norm_squared() + w * w).sqrt();
    [
        (axis.x / n) as f32,
        (axis.y / n) as f32,
        (axis.z / n) as f32,
        (w / n) as f32,
    ]
}
