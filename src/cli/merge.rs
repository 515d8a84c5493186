//! `mbd merge`: the shares of a sweep (`mbd stability --shard K/N`) joined into the CSV and
//! the chart of the unsharded sweep; and the share file that `--shard` writes.

use super::stability::{finish, reference_series, ChartKind};
use super::{create_outputs, exit_unless_failed, say, short, usage};
use mbd::study::sweep::share::{self, Share};
use std::io::Write;
use std::process::ExitCode;

/// `mbd merge --help`.
pub const LONG_ABOUT: &str = "\
Joins the shares of a stability sweep into its CSV and chart.

`mbd stability ... --shard K/N -o share_K.json` runs the K-th of N shares of a sweep: the \
grid's values (K-1) m/N .. K m/N - 1 (of m, counted from 0) with every method, the next \
share's first value with the primary method, and the bisection of the edges that start in its \
values. `mbd merge` reads the N shares (in any order), checks that they come from the same \
model text and options and that none is missing or repeated, follows the modes along the \
whole grid, and writes the same CSV and chart as the unsharded sweep, bit for bit. The \
options of the chart (--chart, --chart-kind, --reference) belong to the merge.

A Slurm job array (docs/cluster.md):
  #SBATCH --array=1-8
  mbd stability models/windmill.mbd --sweep Omega_bar=0.9:2.6:0.01 --shard $SLURM_ARRAY_TASK_ID/8 -o share_$SLURM_ARRAY_TASK_ID.json
and after it:
  mbd merge share_*.json -o stab.csv --chart stab.svg";

#[derive(clap::Args)]
pub struct MergeArgs {
    /// The share files (`mbd stability --shard K/N -o FILE`), all N of them.
    #[arg(required = true, value_name = "SHARE.json")]
    shares: Vec<String>,
    /// Write the sweep's CSV here.
    #[arg(short = 'o', long = "output", value_name = "STAB.csv")]
    output: String,
    /// Write the chart here (PNG for a `.png` name, else SVG).
    #[arg(long, value_name = "STAB.svg")]
    chart: Option<String>,
    /// The chart: the real parts of every mode (real), or the Campbell diagram (campbell).
    #[arg(long, value_enum, default_value = "real")]
    chart_kind: ChartKind,
    /// A CSV whose first column is the param and whose other columns are drawn as lines.
    #[arg(long, value_name = "FILE.csv")]
    reference: Option<String>,
}

pub fn merge(a: MergeArgs) -> ExitCode {
    let mut shares = Vec::with_capacity(a.shares.len());
    for path in &a.shares {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) => return usage(&format!("cannot read share `{path}`: {e}")),
        };
        match serde_json::from_str::<Share>(&text) {
            Ok(s) => shares.push(s),
            Err(e) => {
                return usage(&format!(
                    "`{path}` is not a share of a sweep (`mbd stability --shard K/N -o FILE`): {e}"
                ))
            }
        }
    }
    let (sweep, first) = match share::merge(shares) {
        Ok(x) => x,
        Err(e) => return usage(&e.to_string()),
    };
    let reference = match a.reference.as_deref().map(reference_series).transpose() {
        Ok(r) => r.unwrap_or_default(),
        Err(code) => return code,
    };
    let (mut csv_file, chart_file) = match create_outputs(&a.output, a.chart.as_deref()) {
        Ok(files) => files,
        Err(code) => return code,
    };
    let names = (first.model.as_str(), first.param_label.as_str());
    finish(
        &sweep,
        (&mut csv_file, &a.output),
        chart_file,
        a.chart_kind,
        names,
        reference,
    )
}

/// Writes a share to its file and says what it holds; exit 3 when one of its evaluations
/// failed (the share is written all the same).
pub(super) fn write_share(s: &Share, file: std::fs::File, path: &str) -> ExitCode {
    let mut out = std::io::BufWriter::new(file);
    let written = serde_json::to_writer(&mut out, s)
        .map_err(std::io::Error::from)
        .and_then(|()| out.flush());
    if let Err(e) = written {
        return usage(&format!("cannot write share `{path}`: {e}"));
    }
    let own = share::block(s.values.len(), s.shard, s.shards);
    let span = match (
        s.values.get(own.start),
        own.end.checked_sub(1).and_then(|e| s.values.get(e)),
    ) {
        (Some(a), Some(b)) => format!("{} = {} .. {}", s.param, short(a.0), short(b.0)),
        _ => "no values".to_string(),
    };
    say(&format!(
        "share {}/{}: {span} ({} evaluations, {} bisections, {} edges) written to `{path}`; join the shares with `mbd merge`",
        s.shard,
        s.shards,
        s.points.len(),
        s.refinements.len(),
        s.edges.len()
    ));
    for p in s.points.iter().chain(&s.refinements) {
        if let Some(f) = &p.failure {
            say(&format!(
                "{} = {} ({}): failed: {f}",
                s.param,
                short(p.value.0),
                p.method
            ));
        }
    }
    exit_unless_failed(
        s.points
            .iter()
            .chain(&s.refinements)
            .any(|p| p.failure.is_some()),
    )
}
