//! The `dynrt` command line: parses arguments and calls into the library. Every verb's work is
//! done by library code; this binary only reads arguments, reports errors and sets exit codes.

mod cli;

fn main() {
    std::process::exit(cli::run());
}
