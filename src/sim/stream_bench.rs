//! Runs a [`StreamBench`] (the streaming testbench of `crate::emit::stream_bench`): writes the
//! DUT, the testbench and the vector files into a work directory, compiles and runs them
//! through `crate::sim`, and reads every sink's records back.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::emit::stream_bench::{stream_bench_verilog, StreamBench};
use crate::sim::{self, SimJob, Simulator};

/// Records read back from one run.
#[derive(Debug, Clone)]
pub struct StreamBenchRun {
    /// Per sink (in `StreamBench::sinks` order): its records, each one value per field.
    pub sinks: Vec<Vec<Vec<u64>>>,
    pub compile_seconds: f64,
    pub run_seconds: f64,
}

/// Writes `rtl` (the DUT's Verilog), the testbench and the vector files into `work_dir`, runs
/// `simulator`, and reads every sink. Fails if a tool fails or a sink is short of its expected
/// count (quoting the simulator's output).
pub fn run_stream_bench(
    bench: &StreamBench,
    rtl: &str,
    simulator: Simulator,
    work_dir: &Path,
) -> Result<StreamBenchRun> {
    let tb = stream_bench_verilog(bench)?;
    std::fs::create_dir_all(work_dir)
        .with_context(|| format!("cannot create {}", work_dir.display()))?;
    let write = |name: &str, text: &str| -> Result<PathBuf> {
        let path = work_dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
        Ok(path)
    };
    let dut_file = write(&format!("{}.v", bench.dut), rtl)?;
    let tb_file = write(&format!("tb_{}.v", bench.dut), &tb)?;
    for s in &bench.streams {
        let mut text = String::new();
        for (gap, values) in &s.lines {
            write!(text, "{gap:x}")?;
            for v in values {
                write!(text, " {v:x}")?;
            }
            text.push('\n');
        }
        write(&format!("{}.hex", s.name), &text)?;
    }
    for k in &bench.sinks {
        let _ = std::fs::remove_file(work_dir.join(format!("{}.out.hex", k.name)));
    }
    let job = SimJob::new(work_dir, vec![dut_file, tb_file], "tb");
    let ran = sim::run(simulator, &job)?;
    let mut sinks = Vec::new();
    for k in &bench.sinks {
        let path = work_dir.join(format!("{}.out.hex", k.name));
        let text = std::fs::read_to_string(&path).with_context(|| {
            format!(
                "{simulator} wrote no {}; its output:\n{}{}",
                path.display(),
                ran.stdout,
                ran.stderr
            )
        })?;
        let mut records = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let rec = line
                .split_whitespace()
                .map(|w| u64::from_str_radix(w, 16))
                .collect::<Result<Vec<u64>, _>>()
                .with_context(|| format!("{}:{}: `{line}` is not hex", path.display(), i + 1))?;
            if rec.len() != k.fields.len() {
                bail!(
                    "{}:{}: {} values for {} fields",
                    path.display(),
                    i + 1,
                    rec.len(),
                    k.fields.len()
                );
            }
            records.push(rec);
        }
        if records.len() < k.expected {
            bail!(
                "{simulator}: sink {} got {} of {} records; its output:\n{}{}",
                k.name,
                records.len(),
                k.expected,
                ran.stdout,
                ran.stderr
            );
        }
        sinks.push(records);
    }
    Ok(StreamBenchRun {
        sinks,
        compile_seconds: ran.compile_seconds,
        run_seconds: ran.run_seconds,
    })
}
