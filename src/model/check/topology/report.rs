//! The topology as `mbd check` prints it. Contract: reads the model; must not change it.

use crate::model::*;

/// The topology as `mbd check` prints it.
pub fn report(model: &Model) -> String {
    use std::fmt::Write;
    let d = &model.dofs;
    let mut s = String::new();
    let nodes = model.bodies.len() + model.beams.iter().map(|b| b.nodes.len()).sum::<usize>();
    let coords = d.len() - d.multipliers() - d.extras();
    let _ = writeln!(s, "bodies:");
    for b in &model.bodies {
        let kind = match b.kind {
            BodyKind::PointMass => "point mass, 3 DOFs",
            BodyKind::Rigid => "rigid, 6 DOFs",
        };
        let _ = writeln!(s, "  {:<24} {kind}, mass {} kg", b.name, b.mass);
    }
    for b in &model.beams {
        let _ = writeln!(
            s,
            "  {:<24} beam, {} elements of {} nodes, {} nodes, {} DOFs",
            b.name,
            b.elements,
            b.order,
            b.nodes.len(),
            6 * b.nodes.len()
        );
    }
    if !model.joints.is_empty() {
        let _ = writeln!(s, "joints:");
        for j in &model.joints {
            let extra = if j.kind.extra_unknowns() > 0 {
                " + angle"
            } else {
                ""
            };
            let _ = writeln!(
                s,
                "  {:<24} {} ({} -> {}), {} multipliers{extra}",
                j.name,
                j.kind.name(),
                j.markers[0].text,
                j.markers[1].text,
                j.kind.multipliers()
            );
        }
    }
    if !model.springs.is_empty() || !model.loads.is_empty() || !model.distributed.is_empty() {
        let along = match model.distributed.len() {
            0 => String::new(),
            n => format!(", {n} along beams"),
        };
        let _ = writeln!(
            s,
            "springs and loads: {} springs/dampers, {} loads{along}",
            model.springs.len(),
            model.loads.len()
        );
    }
    if !model.geometry.is_empty() {
        let names: Vec<&str> = model.geometry.iter().map(|g| g.name.as_str()).collect();
        let _ = writeln!(s, "shapes drawn by the view only: {}", names.join(", "));
    }
    let _ = writeln!(
        s,
        "unknowns: {} ({} nodes, {coords} DOFs, {} extra unknowns, {} multipliers), bandwidth {}",
        d.len(),
        nodes,
        d.extras(),
        d.multipliers(),
        d.bandwidth
    );
    let _ = write!(s, "order:");
    let mut line = String::new();
    let mut k = 0;
    while k < d.unknowns.len() {
        let u = d.unknowns[k];
        let (label, width) = match u {
            dofs::Unknown::Translation { body, .. } => {
                let w = if model.bodies[body].kind == BodyKind::Rigid {
                    6
                } else {
                    3
                };
                (model.bodies[body].name.clone(), w)
            }
            dofs::Unknown::NodeTranslation { beam, node, .. } => {
                (format!("{}.node[{node}]", model.beams[beam].name), 6)
            }
            dofs::Unknown::JointAngle { joint } => {
                (format!("{}.angle", model.joints[joint].name), 1)
            }
            dofs::Unknown::Multiplier { joint, .. } => (
                format!("λ {}", model.joints[joint].name),
                model.joints[joint].kind.multipliers(),
            ),
            _ => (String::from("?"), 1),
        };
        let item = format!(" {label} [{k}..{}]", k + width - 1);
        if line.len() + item.len() > 90 {
            let _ = writeln!(s, "{line}");
            line = String::from("      ");
        }
        line.push_str(&item);
        k += width;
    }
    let _ = write!(s, "{line}");
    s
}
