//! Lints Verilog with `verilator --lint-only -Wall` and returns the warnings in structured form.
//!
//! Contract: warnings (`%Warning-CODE: file:line:col: message`) become [`LintWarning`]s, in the
//! order Verilator printed them; a report with none is clean. Errors (`%Error...`, e.g. a syntax
//! error or a missing module) are not lint findings: they make [`lint`] fail with
//! [`ToolError::Compile`] quoting them.

use std::fmt;
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

use super::error::{error_excerpt, ToolError};
use super::process::run_tool;

/// One Verilator warning.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LintWarning {
    /// Verilator's warning code, e.g. "WIDTH", "UNUSEDSIGNAL".
    pub code: String,
    /// The file as Verilator printed it (empty if the warning has no location).
    pub file: String,
    /// 1-based line, 0 if the warning has no location.
    pub line: u32,
    pub message: String,
}

impl fmt::Display for LintWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}: {}: {}",
            self.file, self.line, self.code, self.message
        )
    }
}

/// All warnings of one lint run.
#[derive(Debug, Clone, Default)]
pub struct LintReport {
    pub warnings: Vec<LintWarning>,
}

impl LintReport {
    pub fn is_clean(&self) -> bool {
        self.warnings.is_empty()
    }

    /// The warnings with this code.
    pub fn with_code<'a>(&'a self, code: &'a str) -> impl Iterator<Item = &'a LintWarning> + 'a {
        self.warnings.iter().filter(move |w| w.code == code)
    }
}

impl fmt::Display for LintReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_clean() {
            return writeln!(f, "lint clean");
        }
        writeln!(f, "{} lint warning(s):", self.warnings.len())?;
        for w in &self.warnings {
            writeln!(f, "  {w}")?;
        }
        Ok(())
    }
}

/// `verilator --lint-only -Wall --top-module top files...`, with a 5 minute limit.
pub fn lint(verilog_files: &[PathBuf], top: &str) -> Result<LintReport, ToolError> {
    lint_with_timeout(verilog_files, top, Duration::from_secs(300))
}

pub fn lint_with_timeout(
    verilog_files: &[PathBuf],
    top: &str,
    timeout: Duration,
) -> Result<LintReport, ToolError> {
    if verilog_files.is_empty() {
        return Err(ToolError::BadJob(format!(
            "lint of `{top}`: no source files"
        )));
    }
    for f in verilog_files {
        if !f.is_file() {
            return Err(ToolError::BadJob(format!(
                "lint of `{top}`: source file {} does not exist",
                f.display()
            )));
        }
    }
    let mut cmd = Command::new("verilator");
    cmd.args(["--lint-only", "-Wall", "-Wno-fatal", "--top-module", top])
        .args(verilog_files);
    let out = run_tool("verilator", &format!("linting `{top}`"), &mut cmd, timeout)?;
    let text = out.combined();
    let has_error = text.lines().any(|l| l.starts_with("%Error"));
    if !out.status.success() || has_error {
        let (excerpt, location) = error_excerpt(&text, 10);
        return Err(ToolError::Compile {
            tool: "verilator --lint-only".to_string(),
            top: top.to_string(),
            location,
            excerpt,
        });
    }
    Ok(parse_lint(&text))
}

/// Parses Verilator's warning lines; continuation lines (source excerpts, hints) are skipped.
pub(crate) fn parse_lint(text: &str) -> LintReport {
    let warnings = text
        .lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("%Warning-")?;
            let (code, rest) = rest.split_once(": ")?;
            // "file:line:col: message" or, for global warnings, just "message".
            let mut parts = rest.splitn(4, ':');
            let located = (|| {
                let file = parts.next()?;
                let line: u32 = parts.next()?.trim().parse().ok()?;
                let _col = parts.next()?;
                let message = parts.next()?.trim();
                Some((file.to_string(), line, message.to_string()))
            })();
            let (file, line, message) =
                located.unwrap_or_else(|| (String::new(), 0, rest.trim().to_string()));
            Some(LintWarning {
                code: code.to_string(),
                file,
                line,
                message,
            })
        })
        .collect();
    LintReport { warnings }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_located_and_global_warnings() {
        let text = "%Warning-WIDTH: w.v:3:12: Operator ASSIGNW expects 8 bits on the Assign RHS.\n\
                    \x20                       : ... In instance w\n\
                    \x20   3 |   assign y = a + b;\n\
                    %Warning-MULTITOP: Multiple top level modules\n";
        let r = parse_lint(text);
        assert_eq!(r.warnings.len(), 2);
        assert_eq!(
            r.warnings[0],
            LintWarning {
                code: "WIDTH".into(),
                file: "w.v".into(),
                line: 3,
                message: "Operator ASSIGNW expects 8 bits on the Assign RHS.".into()
            }
        );
        assert_eq!(r.warnings[1].code, "MULTITOP");
        assert_eq!(r.warnings[1].line, 0);
        assert!(!r.is_clean());
        assert!(parse_lint("").is_clean());
    }
}
