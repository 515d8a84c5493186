//! `mbd view`: the model at t = 0 in 3-D, as a self-contained HTML page and, with `--gltf`,
//! a glTF binary; and the recorder behind `mbd run --view/--gltf`, which samples the run's
//! written rows (decimated to at most `view::MAX_FRAMES`).

use super::{compile, read, usage, Format};
use mbd::output::view::{self, History};
use mbd::runtime::scene::{Frames, Scene};
use mbd::runtime::State;
use mbd::Compiled;
use std::process::ExitCode;

/// `mbd view --help`.
pub const LONG_ABOUT: &str = "\
The model at t = 0 in 3-D, in one HTML file that opens offline in a browser (three.js \
embedded): rigid bodies as boxes sized from their inertia, point masses as spheres, rigid \
beams as cylinders, elastic beams as tubes through their nodes with each node's section axes, \
joints by kind along their axes (revolute and cylindrical: a cylinder; prismatic: a bar; \
spherical: a ball; fixed: a cube; distance: a rod), springs as coils, loads as arrows, the \
ground as a grid normal to gravity. Hover a part for its name, kind and properties with \
units; drag to turn the view, scroll to zoom.

`mbd run MODEL --view VIEW.html` draws the same scene animated from the run, with play, \
pause, speed, a time slider, the time histories of chosen channels under the scene (the \
cursor follows the animation), and the path of a part (double-click it). --gltf OUT.glb \
writes a glTF 2.0 binary of the same meshes (and, from a run, the animation), which Blender \
and any glTF viewer open.

Examples:
  mbd view models/windmill.mbd -o windmill_view.html
  mbd run models/windmill.mbd --view windmill.html --gltf windmill.glb -o windmill.csv";

#[derive(clap::Args)]
pub struct ViewArgs {
    /// The model file.
    model: String,
    /// Override a param: NAME=VALUE, VALUE in SI units or with units.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// Write the HTML view here.
    #[arg(short = 'o', long = "output", value_name = "VIEW.html")]
    output: Option<String>,
    /// Write a glTF binary here.
    #[arg(long, value_name = "OUT.glb")]
    gltf: Option<String>,
}

pub fn view(a: ViewArgs) -> ExitCode {
    if a.output.is_none() && a.gltf.is_none() {
        return usage("say where to write the view: -o VIEW.html and/or --gltf OUT.glb");
    }
    let text = match read(&a.model) {
        Ok(t) => t,
        Err(code) => return code,
    };
    let c = match compile(&a.model, &text, &a.set, Default::default(), Format::Human) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let mut rec = Recorder::new(&c, 1);
    rec.sample(&c.lowered.system.initial, &[]);
    rec.histories.clear();
    match rec.write(&c, a.output.as_deref(), a.gltf.as_deref()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}

/// The scene and its samples along a run.
pub struct Recorder {
    scene: Scene,
    frames: Frames,
    histories: Vec<History>,
    stride: usize,
    seen: usize,
    /// The last row, when it was not sampled: kept so the view ends where the run ended.
    tail: Option<(Frames, Vec<f64>)>,
}

impl Recorder {
    /// For a run writing about `rows` rows.
    pub fn new(c: &Compiled, rows: usize) -> Recorder {
        let histories = c
            .model
            .outputs
            .iter()
            .map(|o| History {
                name: o.column.clone(),
                unit: mbd::channel_unit(c, &o.column).unwrap_or_default(),
                values: Vec::new(),
            })
            .collect();
        Recorder {
            scene: mbd::scene(c),
            frames: Frames::default(),
            histories,
            stride: view::stride(rows),
            seen: 0,
            tail: None,
        }
    }

    /// A written row: sampled every `stride` rows; the last one is kept aside.
    pub fn sample(&mut self, st: &State, values: &[f64]) {
        let keep = self.seen.is_multiple_of(self.stride);
        self.seen += 1;
        if keep {
            self.scene.sample(st, &mut self.frames);
            for (h, v) in self.histories.iter_mut().zip(values) {
                h.values.push(*v);
            }
            self.tail = None;
        } else {
            let mut f = Frames::default();
            self.scene.sample(st, &mut f);
            self.tail = Some((f, values.to_vec()));
        }
    }

    /// Writes the HTML page and the glTF file asked for (usage errors exit 2).
    pub fn write(
        &mut self,
        c: &Compiled,
        html: Option<&str>,
        glb: Option<&str>,
    ) -> Result<(), ExitCode> {
        if let Some((f, values)) = self.tail.take() {
            self.frames.t.extend(f.t);
            self.frames.positions.extend(f.positions);
            self.frames.rotations.extend(f.rotations);
            self.frames.loads.extend(f.loads);
            for (h, v) in self.histories.iter_mut().zip(values) {
                h.values.push(v);
            }
        }
        self.scene.finish(&mut self.frames);
        let title = match &c.model.title {
            Some(t) => format!("{}: {t}", c.model.name),
            None => c.model.name.clone(),
        };
        let create = |p: &str| {
            std::fs::File::create(p)
                .map(std::io::BufWriter::new)
                .map_err(|e| usage(&format!("cannot create `{p}`: {e}")))
        };
        if let Some(p) = html {
            let mut f = create(p)?;
            view::write_html(&mut f, &title, &self.scene, &self.frames, &self.histories)
                .and_then(|()| std::io::Write::flush(&mut f))
                .map_err(|e| usage(&format!("cannot write `{p}`: {e}")))?;
        }
        if let Some(p) = glb {
            let mut f = create(p)?;
            mbd::output::gltf::write_glb(&mut f, &title, &self.scene, &self.frames)
                .and_then(|()| std::io::Write::flush(&mut f))
                .map_err(|e| usage(&format!("cannot write `{p}`: {e}")))?;
        }
        Ok(())
    }
}
