//! Output: trajectories -> files (CSV now; JSON summaries).
//!
//! Contract: writes what the runtime's probes measure; one header row (`t`, then the channels
//! as the model names them), one row per written step, SI values at full round-trip precision.
//! Rows are written as they come, so a failed run keeps every row computed before the failure.

pub mod charts;
pub mod gltf;
mod guides;
mod legend;
mod number;
pub mod raster;
pub mod ticks;
pub mod view;

use crate::runtime::{Augment, State, System};
use std::io::{self, Write};

pub struct CsvWriter<W: Write> {
    out: io::BufWriter<W>,
    line: Vec<u8>,
    digits: zmij::Buffer,
}

impl<W: Write> CsvWriter<W> {
    pub fn new(out: W, sys: &System) -> io::Result<CsvWriter<W>> {
        let mut w = CsvWriter {
            out: io::BufWriter::new(out),
            line: Vec::new(),
            digits: zmij::Buffer::new(),
        };
        let mut header = String::from("t");
        for c in &sys.channels {
            header.push(',');
            header.push_str(&c.column);
        }
        writeln!(w.out, "{header}")?;
        Ok(w)
    }

    pub fn row(&mut self, sys: &System, st: &State, aug: Augment) -> io::Result<()> {
        self.line.clear();
        // The shortest text that reads back to the same f64, as `{:?}` writes it
        // (`number.rs`). `+ 0.0` turns a negative zero into zero.
        number::push(&mut self.line, &mut self.digits, st.t + 0.0);
        let (line, digits) = (&mut self.line, &mut self.digits);
        sys.probe_each(sys.channels.iter().map(|c| &c.probe), st, aug, |x| {
            line.push(b',');
            number::push(line, digits, x + 0.0);
        });
        self.line.push(b'\n');
        self.out.write_all(&self.line)
    }

    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

/// Reads a CSV written by [`CsvWriter`] (for tests and tools): header and numeric rows.
pub fn read_csv(text: &str) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or("empty CSV")?
        .split(',')
        .map(str::to_string)
        .collect();
    let mut rows = Vec::new();
    for (k, l) in lines.enumerate() {
        let row: Result<Vec<f64>, _> = l.split(',').map(|x| x.parse::<f64>()).collect();
        let row = row.map_err(|e| format!("row {}: {e}", k + 1))?;
        if row.len() != header.len() {
            return Err(format!(
                "row {} has {} fields, header {}",
                k + 1,
                row.len(),
                header.len()
            ));
        }
        rows.push(row);
    }
    Ok((header, rows))
}
