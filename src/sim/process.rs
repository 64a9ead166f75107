//! Runs one external tool (iverilog, vvp, verilator, a Verilator model, yosys) with a time limit.
//!
//! Contract: the child runs in its own process group so that a timeout kills the whole tree
//! (Verilator starts make, which starts g++); stdout and stderr are drained on their own threads
//! so a chatty simulation can never block on a full pipe, and lines starting with
//! `crate::progress::HEARTBEAT` are reported as they arrive; a missing binary becomes
//! [`ToolError::NotFound`] with the install hint, never a bare "No such file or directory".
//!
//! Since the child's group is not the terminal's, Ctrl-C reaches only dynrt: with
//! [`forward_signals`] installed (the CLI does it first thing), SIGINT, SIGTERM and SIGHUP are
//! forwarded to every running tool's group, dynrt waits for the groups to end (SIGKILL after
//! [`SIGNAL_GRACE`]), removes the outputs of the interrupted run
//! ([`crate::output::abandon_all`]) and exits with 128 + the signal's number, as a shell does.

use std::io::Read;
use std::os::unix::process::CommandExt;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::error::ToolError;

/// How long to wait for output pipes to close after the child has exited or been killed.
const PIPE_GRACE: Duration = Duration::from_secs(5);
/// How long a forwarded signal has to end a tool's group before SIGKILL does.
pub const SIGNAL_GRACE: Duration = Duration::from_secs(3);

/// The process groups of the tools running now (each child leads its own group).
static RUNNING_GROUPS: Mutex<Vec<i32>> = Mutex::new(Vec::new());

fn running_groups() -> std::sync::MutexGuard<'static, Vec<i32>> {
    RUNNING_GROUPS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Whether any process of group `pgid` is alive; reaps the leader if it is our exited child.
fn group_alive(pgid: i32) -> bool {
    // SAFETY: waitpid and kill take plain integers; a null status pointer is allowed.
    unsafe {
        libc::waitpid(pgid, std::ptr::null_mut(), libc::WNOHANG);
        libc::kill(-pgid, 0) == 0
    }
}

/// Sends `signal` to every group, waits up to `grace` for them to end, then kills the rest.
fn end_groups(groups: &[i32], signal: i32, grace: Duration) {
    for &g in groups {
        // SAFETY: kill with a negative pid signals a process group; no memory is involved.
        unsafe { libc::kill(-g, signal) };
    }
    let start = Instant::now();
    while groups.iter().any(|&g| group_alive(g)) && start.elapsed() < grace {
        std::thread::sleep(Duration::from_millis(20));
    }
    for &g in groups {
        if group_alive(g) {
            // SAFETY: as above.
            unsafe { libc::kill(-g, libc::SIGKILL) };
        }
    }
}

/// Set when a signal is being handled: from then on the signal thread alone ends the process.
static INTERRUPTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Blocks for good when a signal is being handled, so that the thread that saw its tool die
/// does not report the death as the tool's failure, clean up while the tool's group is still
/// ending, or exit first; the signal thread exits the process.
pub fn wait_if_interrupted() {
    while INTERRUPTED.load(std::sync::atomic::Ordering::SeqCst) {
        std::thread::sleep(Duration::from_secs(1));
    }
}

/// Installs the signal forwarding of the module doc (once; later calls do nothing).
pub fn forward_signals() -> std::io::Result<()> {
    static INSTALLED: std::sync::OnceLock<()> = std::sync::OnceLock::new();
    if INSTALLED.get().is_some() {
        return Ok(());
    }
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    let _ = INSTALLED.set(());
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            INTERRUPTED.store(true, std::sync::atomic::Ordering::SeqCst);
            let groups = running_groups().clone();
            if !groups.is_empty() {
                eprintln!(
                    "dynrt: signal {signal}: ending {} running tool(s) and removing this run's output",
                    groups.len()
                );
            }
            end_groups(&groups, signal, SIGNAL_GRACE);
            crate::output::abandon_all();
            std::process::exit(128 + signal);
        }
    });
    Ok(())
}

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
    // The list stays locked from before the spawn until the group is in it, so a signal that
    // arrives meanwhile waits for the list and finds the new group there (else the tool would
    // run on after dynrt exits).
    let mut groups = running_groups();
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
    let pgid = child.id() as i32;
    groups.push(pgid);
    drop(groups);
    let out_reader = drain(child.stdout.take());
    let err_reader = drain(child.stderr.take());

    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) => {}
            Err(e) => {
                // The signal thread may have reaped the child already.
                wait_if_interrupted();
                kill_group(&mut child);
                running_groups().retain(|&g| g != pgid);
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
    running_groups().retain(|&g| g != pgid);
    wait_if_interrupted();
    let seconds = start.elapsed().as_secs_f64();
    // The whole group is dead or done by now, so the pipes close at once; a grandchild that
    // left the group (setsid) could hold them open forever, hence the bounded wait.
    let stdout = join(out_reader, PIPE_GRACE);
    let stderr = join(err_reader, PIPE_GRACE);
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

/// Output collected by a reader thread; shared so that it can be taken even if the thread is
/// still blocked on a pipe that an escaped grandchild holds open.
struct Reader {
    buffer: Arc<Mutex<Vec<u8>>>,
    handle: JoinHandle<()>,
}

fn drain<R: Read + Send + 'static>(pipe: Option<R>) -> Option<Reader> {
    pipe.map(|mut p| {
        let buffer = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&buffer);
        let handle = std::thread::spawn(move || {
            let mut chunk = [0u8; 8192];
            // The unfinished last line, scanned for the testbench's heartbeat.
            let mut line = Vec::new();
            loop {
                match p.read(&mut chunk) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => {
                        sink.lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .extend_from_slice(&chunk[..n]);
                        for &b in &chunk[..n] {
                            if b == b'\n' {
                                if let Some(h) =
                                    line.strip_prefix(crate::progress::HEARTBEAT.as_bytes())
                                {
                                    crate::progress::report(&String::from_utf8_lossy(h));
                                }
                                line.clear();
                            } else if line.len() < 256 {
                                line.push(b);
                            }
                        }
                    }
                }
            }
        });
        Reader { buffer, handle }
    })
}

/// Waits up to `grace` for the pipe to reach end of file, then takes what was read.
fn join(reader: Option<Reader>, grace: Duration) -> String {
    let Some(reader) = reader else {
        return String::new();
    };
    let start = Instant::now();
    while !reader.handle.is_finished() && start.elapsed() < grace {
        std::thread::sleep(Duration::from_millis(5));
    }
    let bytes = reader.buffer.lock().unwrap_or_else(|e| e.into_inner());
    String::from_utf8_lossy(&bytes).into_owned()
}

/// Kills the child's whole process group (the child is its leader), then reaps the child.
fn kill_group(child: &mut Child) {
    // SAFETY: kill with a negative pid signals the child's group; no memory is involved.
    unsafe { libc::kill(-(child.id() as i32), libc::SIGKILL) };
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Heartbeat lines reach the progress listener while the tool runs; others do not.
    #[test]
    fn heartbeat_lines_are_reported_as_they_arrive() {
        crate::progress::seen_in_tests();
        let out = run_tool(
            "sh",
            "testing",
            Command::new("sh").args([
                "-c",
                "echo dynrt-heartbeat frame 0: 10 cycles, 1 rays; echo other; \
                 printf 'dynrt-heartbeat frame 1: 20 cycles, 2 rays\\n'",
            ]),
            Duration::from_secs(30),
        )
        .unwrap();
        assert!(out.stdout.contains("other"));
        // (Other tests' simulations may report beside these.)
        let seen = crate::progress::seen_in_tests();
        let first = seen.iter().position(|m| m == "frame 0: 10 cycles, 1 rays");
        let second = seen.iter().position(|m| m == "frame 1: 20 cycles, 2 rays");
        assert!(
            matches!((first, second), (Some(a), Some(b)) if a < b),
            "{seen:?}"
        );
        assert!(!seen.iter().any(|m| m.contains("other")), "{seen:?}");
    }
}
