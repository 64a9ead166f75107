//! Runs one external tool (iverilog, vvp, verilator, a Verilator model, yosys) with a time limit.
//!
//! Contract: the child runs in its own process group so that a timeout kills the whole tree
//! (Verilator starts make, which starts g++); stdout and stderr are drained on their own threads
//! so a chatty simulation can never block on a full pipe; a missing binary becomes
//! [`ToolError::NotFound`] with the install hint, never a bare "No such file or directory".

use std::io::Read;
use std::os::unix::process::CommandExt;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::error::ToolError;

/// What a finished (not timed-out) tool run produced.
#[derive(Debug)]
pub(crate) struct ToolOutput {
    pub status: ExitStatus,
    pub stdout: String,
    pub stderr: String,
    pub seconds: f64,
}

impl ToolOutput {
    /// stdout followed by stderr, for error excerpts that must not miss either stream.
    pub fn combined(&self) -> String {
        combine(&self.stdout, &self.stderr)
    }
}

pub(crate) fn combine(stdout: &str, stderr: &str) -> String {
    let mut all = String::with_capacity(stdout.len() + stderr.len() + 1);
    all.push_str(stdout);
    if !stdout.is_empty() && !stdout.ends_with('\n') {
        all.push('\n');
    }
    all.push_str(stderr);
    all
}

/// Runs `cmd` to completion or until `timeout`; `stage` names the step for error messages
/// (e.g. "compiling tb_adder").
pub(crate) fn run_tool(
    tool: &str,
    stage: &str,
    cmd: &mut Command,
    timeout: Duration,
) -> Result<ToolOutput, ToolError> {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0);
    let start = Instant::now();
    let mut child = cmd.spawn().map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            ToolError::NotFound {
                tool: tool.to_string(),
            }
        } else {
            ToolError::Io {
                context: format!("cannot start {tool} ({stage})"),
                source: e,
            }
        }
    })?;
    let out_reader = drain(child.stdout.take());
    let err_reader = drain(child.stderr.take());

    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) => {}
            Err(e) => {
                kill_group(&mut child);
                return Err(ToolError::Io {
                    context: format!("waiting for {tool} ({stage})"),
                    source: e,
                });
            }
        }
        if start.elapsed() >= timeout {
            kill_group(&mut child);
            break None;
        }
        // Short sleeps early keep tiny runs fast; longer ones later keep polling cheap.
        let pause = if start.elapsed() < Duration::from_secs(1) {
            Duration::from_millis(5)
        } else {
            Duration::from_millis(50)
        };
        std::thread::sleep(pause);
    };
    let seconds = start.elapsed().as_secs_f64();
    let stdout = join(out_reader);
    let stderr = join(err_reader);
    match status {
        Some(status) => Ok(ToolOutput {
            status,
            stdout,
            stderr,
            seconds,
        }),
        None => Err(ToolError::Timeout {
            tool: tool.to_string(),
            stage: stage.to_string(),
            seconds: timeout.as_secs_f64(),
            excerpt: last_lines(&combine(&stdout, &stderr), 10),
        }),
    }
}

fn drain<R: Read + Send + 'static>(pipe: Option<R>) -> Option<JoinHandle<String>> {
    pipe.map(|mut p| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = p.read_to_end(&mut bytes);
            String::from_utf8_lossy(&bytes).into_owned()
        })
    })
}

fn join(reader: Option<JoinHandle<String>>) -> String {
    reader.and_then(|h| h.join().ok()).unwrap_or_default()
}

/// Kills the child's whole process group (the child is its leader), then reaps the child.
fn kill_group(child: &mut Child) {
    let pgid = child.id();
    // std has no killpg; /bin/kill with a negative id signals the group.
    let _ = Command::new("kill")
        .args(["-KILL", "--", &format!("-{pgid}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    let _ = child.kill();
    let _ = child.wait();
}

/// The last `n` non-empty lines of `text`.
pub(crate) fn last_lines(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    if lines.is_empty() {
        return "(no output)".to_string();
    }
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// Describes an exit status for humans: "exit status 1" or "killed by signal 6".
pub(crate) fn describe_status(status: &ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(code), _) => format!("exit status {code}"),
        (None, Some(sig)) => format!("killed by signal {sig}"),
        _ => status.to_string(),
    }
}
