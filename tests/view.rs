//! Issue 25: the 3-D view. The HTML page's data (the scene's shapes, the sampled poses and
//! the channels' histories) against the run's CSV; the glTF binary read back and validated by
//! the `gltf` crate (structure, accessor bounds, the animation against the run).

use crate::cli::{code, mbd, stderr, temp};
use base64::Engine;

fn floats(b64: &serde_json::Value) -> Vec<f32> {
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(b64.as_str().expect("base64 text"))
        .expect("base64");
    bytes
        .chunks(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// The JSON the page carries.
fn page_data(html: &str) -> serde_json::Value {
    let tag = "<script id=\"mbd-data\" type=\"application/json\">";
    let start = html.find(tag).expect("data") + tag.len();
    let end = start + html[start..].find("</script>").expect("end of data");
    serde_json::from_str(&html[start..end].replace("<\\/", "</")).expect("JSON")
}

#[test]
fn a_run_view_follows_the_pendulum_as_its_csv_says() {
    let (html, glb, csv) = (temp("p.html", ""), temp("p.glb", ""), temp("p.csv", ""));
    let o = mbd(&[
        "run",
        "models/pendulum.mbd",
        "--view",
        html.to_str().expect("path"),
        "--gltf",
        glb.to_str().expect("path"),
        "-o",
        csv.to_str().expect("path"),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let text = std::fs::read_to_string(&html).expect("html");
    assert!(text.starts_with("<!DOCTYPE html>"));
    // Self-contained: no address to fetch.
    assert!(!text.contains("src=\"http") && !text.contains("href=\"http"));
    let d = page_data(&text);
    let (_, rows) =
        mbd::output::read_csv(&std::fs::read_to_string(&csv).expect("csv")).expect("parse");
    let t: Vec<f64> = serde_json::from_value(d["t"].clone()).expect("t");
    // 201 rows, all kept (fewer than view::MAX_FRAMES).
    assert_eq!(t.len(), rows.len());
    let shapes = d["shapes"].as_array().expect("shapes");
    let bob = shapes
        .iter()
        .find(|s| s["name"] == "bob")
        .expect("the bob's shape");
    assert_eq!(bob["kind"], "point mass");
    assert_eq!(bob["info"], "1 kg");
    let link = shapes.iter().find(|s| s["name"] == "link").expect("link");
    assert_eq!(link["kind"], "distance joint");
    assert_eq!(link["look"]["type"], "link");
    let anchors = d["anchors"].as_u64().expect("anchors") as usize;
    let p = floats(&d["positions"]);
    let q = floats(&d["rotations"]);
    assert_eq!(p.len(), 3 * anchors * t.len());
    assert_eq!(q.len(), 4 * anchors * t.len());
    let a = bob["anchor"].as_u64().expect("anchor") as usize;
    // The bob's anchor is where the CSV's x and y put it, to f32's rounding.
    let mut worst = 0.0f64;
    for (k, r) in rows.iter().enumerate() {
        assert!((t[k] - r[0]).abs() <= 1e-12, "{} {}", t[k], r[0]);
        let at = 3 * (k * anchors + a);
        worst = worst
            .max((p[at] as f64 - r[1]).abs())
            .max((p[at + 1] as f64 - r[2]).abs());
    }
    assert!(worst < 1e-7, "{worst}");
    // Each channel's history, per sample.
    let hist = d["histories"].as_array().expect("histories");
    assert_eq!(hist[0]["name"], "x");
    assert_eq!(hist[0]["unit"], "m");
    assert_eq!(hist[6]["name"], "tension");
    assert_eq!(hist[6]["unit"], "N");
    let tension = floats(&hist[6]["values"]);
    assert_eq!(tension.len(), rows.len());
    assert!(tension
        .iter()
        .zip(&rows)
        .all(|(v, r)| (*v as f64 - r[7]).abs() <= 1e-6 * r[7].abs()));
    // Unit quaternions.
    assert!(q
        .chunks(4)
        .all(|c| (c.iter().map(|x| x * x).sum::<f32>() - 1.0).abs() < 1e-6));

    // The glTF binary: valid, and the link's node follows the bob.
    let bytes = std::fs::read(&glb).expect("glb");
    let g = gltf::Gltf::from_slice(&bytes).expect("a valid glTF binary");
    let blob = g.blob.as_deref().expect("binary chunk");
    check_bounds(&g, blob);
    let anim = g.animations().next().expect("an animation");
    let link_node = g
        .nodes()
        .find(|n| n.name() == Some("link"))
        .expect("link node");
    let channel = anim
        .channels()
        .find(|c| {
            c.target().node().index() == link_node.index()
                && matches!(c.target().property(), gltf::animation::Property::Scale)
        })
        .expect("the link's scale");
    let lengths = read(blob, &channel.sampler().output());
    let times = read(blob, &channel.sampler().input());
    assert_eq!(times.len(), rows.len());
    // The link's length (the scale along its axis) is the rope's, 0.5 m.
    for s in lengths.chunks(3) {
        assert!((s[1] - 0.5).abs() < 1e-6, "{s:?}");
    }
}

/// The floats of an accessor.
fn read(blob: &[u8], a: &gltf::Accessor) -> Vec<f32> {
    let v = a.view().expect("buffer view");
    let at = v.offset() + a.offset();
    let n = a.count() * a.dimensions().multiplicity();
    (0..n)
        .map(|i| {
            let o = at + 4 * i;
            f32::from_le_bytes([blob[o], blob[o + 1], blob[o + 2], blob[o + 3]])
        })
        .collect()
}

/// Every accessor's data lies within its declared min and max, which are attained.
fn check_bounds(g: &gltf::Gltf, blob: &[u8]) {
    for a in g.accessors() {
        let width = a.dimensions().multiplicity();
        let v = read(blob, &a);
        let (Some(lo), Some(hi)) = (a.min(), a.max()) else {
            panic!("accessor {} has no bounds", a.index());
        };
        let lo: Vec<f32> = serde_json::from_value(lo).expect("min");
        let hi: Vec<f32> = serde_json::from_value(hi).expect("max");
        for k in 0..width {
            let col: Vec<f32> = v.iter().skip(k).step_by(width).copied().collect();
            let (mn, mx) = col
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), x| {
                    (a.min(*x), b.max(*x))
                });
            assert_eq!((mn, mx), (lo[k], hi[k]), "accessor {}", a.index());
        }
    }
}

#[test]
fn a_view_of_the_windmill_at_rest_and_its_gltf() {
    let (html, glb) = (temp("w.html", ""), temp("w.glb", ""));
    let o = mbd(&[
        "view",
        "models/windmill.mbd",
        "-o",
        html.to_str().expect("path"),
        "--gltf",
        glb.to_str().expect("path"),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let d = page_data(&std::fs::read_to_string(&html).expect("html"));
    assert_eq!(d["t"].as_array().map(Vec::len), Some(1));
    let shapes = d["shapes"].as_array().expect("shapes");
    let kinds = |k: &str| shapes.iter().filter(|s| s["kind"] == k).count();
    // Four blades and their hub and tower top as bodies, four lag hinges and the drive.
    assert!(kinds("rigid body") >= 6, "{shapes:?}");
    assert_eq!(kinds("revolute joint"), 5);
    let blade = shapes
        .iter()
        .find(|s| {
            s["name"].as_str().is_some_and(|n| n.contains("blade")) && s["kind"] == "rigid body"
        })
        .expect("a blade");
    assert!(blade["info"].as_str().expect("info").contains("kg*m^2"));
    assert_eq!(blade["look"]["type"], "box");
    let bytes = std::fs::read(&glb).expect("glb");
    let g = gltf::Gltf::from_slice(&bytes).expect("a valid glTF binary");
    check_bounds(&g, g.blob.as_deref().expect("blob"));
    assert_eq!(g.animations().count(), 0);
    assert!(g.meshes().count() >= 11);
    // A usage error without an output.
    let o = mbd(&["view", "models/windmill.mbd"]);
    assert_eq!(code(&o), 2);
}

/// The "done when": the windmill's view shows the rotor whirling on its tower. At
/// Omega_bar = 2 (inside the ground-resonance band) the hub's motion grows from 1e-4 m to
/// about 0.8 m by t = 8 s; the slider tower draws its mast (`height = h`, a shape with no
/// mass), a cylinder from the ground 3.6 m below to the top, whose top follows the CSV's hub.
#[test]
fn the_windmill_view_shows_the_rotor_whirling_on_its_tower() {
    let (html, csv) = (temp("whirl.html", ""), temp("whirl.csv", ""));
    let o = mbd(&[
        "run",
        "models/windmill.mbd",
        "--set",
        "Omega_bar=2",
        "--until",
        "8",
        "--view",
        html.to_str().expect("path"),
        "-o",
        csv.to_str().expect("path"),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let d = page_data(&std::fs::read_to_string(&html).expect("html"));
    let shapes = d["shapes"].as_array().expect("shapes");
    let mast = shapes
        .iter()
        .find(|s| s["name"] == "tower.mast")
        .expect("the tower's mast");
    assert_eq!(mast["kind"], "shape (drawn only)");
    assert_eq!(mast["look"]["type"], "link");
    assert!((mast["look"]["radius"].as_f64().expect("radius") - 0.12).abs() < 1e-12);
    let (bottom, top) = (
        mast["anchor"].as_u64().expect("anchor") as usize,
        mast["look"]["to"].as_u64().expect("to") as usize,
    );
    let anchors = d["anchors"].as_u64().expect("anchors") as usize;
    let t: Vec<f64> = serde_json::from_value(d["t"].clone()).expect("t");
    let p = floats(&d["positions"]);
    let (_, rows) =
        mbd::output::read_csv(&std::fs::read_to_string(&csv).expect("csv")).expect("parse");
    // 16,001 rows decimated to at most 3,000 samples, each at a row's time.
    assert!(t.len() <= 3000 && t.len() > 2000, "{}", t.len());
    let (mut row, mut worst, mut reach) = (0, 0.0f64, 0.0f64);
    for (k, tk) in t.iter().enumerate() {
        while (rows[row][0] - tk).abs() > 1e-9 {
            row += 1;
        }
        let at = |a: usize| [0, 1, 2].map(|i| p[3 * (k * anchors + a) + i] as f64);
        let (b, x) = (at(bottom), at(top));
        assert!(
            b.iter()
                .zip([0.0, 0.0, -3.6])
                .all(|(u, v)| (u - v).abs() < 1e-6),
            "{b:?}"
        );
        worst = worst
            .max((x[0] - rows[row][1]).abs())
            .max(x[1].abs())
            .max(x[2].abs());
        reach = reach.max(x[0].abs());
    }
    // The top follows the hub to f32's rounding (measured 2.9e-8 m); the mast leans by up
    // to 0.8 m over its 3.6 m, 13 degrees (measured 0.825 m).
    assert!(worst < 1e-7, "{worst}");
    assert!(reach > 0.6 && reach < 1.0, "{reach}");
}

/// A body with products of inertia is drawn as the uniform box of its principal moments along
/// its principal axes: the box's axes (its anchor's quaternion) and half-sizes give back the
/// inertia tensor.
#[test]
fn a_body_with_products_of_inertia_is_drawn_along_its_principal_axes() {
    let model = temp(
        "products.mbd",
        "model products
ground earth
rigid plate {
    mass = 2 kg, at = (0, 0, 1) m, orientation = rotate(z, 30 deg)
    inertia = (2, 3, 4) kg*m^2, products = (0.5, -0.25, 0.2) kg*m^2
}
joint pin = spherical(earth @ (0, 0, 1) m, plate)
output z = plate.position.z
solve hht { dt = 1 ms, until = 0.01 s }
",
    );
    let html = temp("products.html", "");
    let o = mbd(&[
        "view",
        model.to_str().expect("path"),
        "-o",
        html.to_str().expect("path"),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let d = page_data(&std::fs::read_to_string(&html).expect("html"));
    let shapes = d["shapes"].as_array().expect("shapes");
    let plate = shapes
        .iter()
        .find(|s| s["name"] == "plate")
        .expect("the plate");
    assert!(plate["info"]
        .as_str()
        .expect("info")
        .contains("principal moments"));
    let axes = shapes
        .iter()
        .find(|s| s["name"] == "plate axes")
        .expect("the plate's axes");
    let q = floats(&d["rotations"]);
    let quat = |a: &serde_json::Value| {
        let k = a["anchor"].as_u64().expect("anchor") as usize;
        let [x, y, z, w] = [0, 1, 2, 3].map(|i| q[4 * k + i] as f64);
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
    };
    // The box's axes in the body's axes.
    let p = (quat(axes).inverse() * quat(plate)).to_rotation_matrix();
    let h: Vec<f64> = serde_json::from_value(plate["look"]["half"].clone()).expect("half");
    let m = 2.0;
    let moments = nalgebra::Vector3::new(
        m * (h[1] * h[1] + h[2] * h[2]) / 3.0,
        m * (h[0] * h[0] + h[2] * h[2]) / 3.0,
        m * (h[0] * h[0] + h[1] * h[1]) / 3.0,
    );
    let back = p.matrix() * nalgebra::Matrix3::from_diagonal(&moments) * p.matrix().transpose();
    let diag = [2.0, 3.0, 4.0];
    let prods = [((0, 1), 0.5), ((0, 2), -0.25), ((1, 2), 0.2)];
    let mut worst = 0.0f64;
    for (k, v) in diag.iter().enumerate() {
        worst = worst.max((back[(k, k)] - v).abs());
    }
    // Whatever the sign convention of the products, their magnitudes come back.
    for ((i, j), v) in prods {
        worst = worst.max((back[(i, j)].abs() - f64::abs(v)).abs());
        assert!((back[(i, j)] - back[(j, i)]).abs() < 1e-5);
    }
    // f32 quaternions: measured 6.1e-8 kg*m^2.
    assert!(worst < 2e-7, "{back} {worst}");
}

/// A spring in the glTF binary is the HTML view's helix: 8 turns of radius r about the unit
/// link's axis (y, from -1/2 to 1/2), its wire r / 6 thick, every triangle facing outward.
#[test]
fn a_spring_in_the_gltf_is_a_helix_facing_outward() {
    let model = temp(
        "spring_glb.mbd",
        "model sprung
ground earth
rigid bob { mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0, -1, 0) m }
spring hang(earth, bob) { stiffness = 100 N/m }
joint rail = prismatic(earth, bob) { axis = y }
output y = bob.position.y
solve hht { dt = 1 ms, until = 0.01 s }
",
    );
    let (glb, html) = (temp("spring.glb", ""), temp("spring.html", ""));
    let o = mbd(&[
        "view",
        model.to_str().expect("path"),
        "-o",
        html.to_str().expect("path"),
        "--gltf",
        glb.to_str().expect("path"),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let bytes = std::fs::read(&glb).expect("glb");
    let g = gltf::Gltf::from_slice(&bytes).expect("a valid glTF binary");
    let blob = g.blob.as_deref().expect("blob");
    check_bounds(&g, blob);
    let mesh = g
        .meshes()
        .find(|m| m.name() == Some("hang"))
        .expect("the spring's mesh");
    let prim = mesh.primitives().next().expect("primitive");
    let p = read(
        blob,
        &prim.get(&gltf::Semantic::Positions).expect("positions"),
    );
    let n = read(blob, &prim.get(&gltf::Semantic::Normals).expect("normals"));
    // 8 turns of 24 segments, 6 around the wire, two triangles each.
    assert_eq!(p.len(), 3 * 8 * 24 * 6 * 6);
    let d = page_data(&std::fs::read_to_string(&html).expect("html"));
    let shapes = d["shapes"].as_array().expect("shapes");
    let spring = shapes.iter().find(|s| s["name"] == "hang").expect("hang");
    assert_eq!(spring["look"]["coils"], 8);
    let r = spring["look"]["radius"].as_f64().expect("radius");
    let wire = r / 6.0;
    for v in p.chunks(3) {
        let radial = (v[0] as f64).hypot(v[2] as f64);
        assert!(
            (radial - r).abs() <= wire * 1.0001 && (v[1] as f64).abs() <= 0.5 + wire,
            "{v:?}"
        );
    }
    for (t, m) in p.chunks(9).zip(n.chunks(9)) {
        let at = |k: usize| nalgebra::Vector3::new(t[3 * k], t[3 * k + 1], t[3 * k + 2]);
        let face = (at(1) - at(0)).cross(&(at(2) - at(0)));
        let mean =
            nalgebra::Vector3::new(m[0] + m[3] + m[6], m[1] + m[4] + m[7], m[2] + m[5] + m[8]);
        assert!(face.dot(&mean) > 0.0, "a triangle faces inward: {t:?}");
    }
}
