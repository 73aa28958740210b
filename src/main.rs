//! The `kneeform` command line: parses flags, runs one command, prints one
//! clear line on error (exit 2) and never a backtrace.

mod cli;

use std::process::ExitCode;

use clap::Parser;

use cli::args::{Cli, Command};

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(&cli) {
        Ok(code) => code,
        Err(err) => {
            if is_broken_pipe(&err) {
                return ExitCode::SUCCESS;
            }
            eprintln!("kneeform: error: {}", cli::one_line(&err));
            ExitCode::from(2)
        }
    }
}

fn run(cli: &Cli) -> anyhow::Result<ExitCode> {
    match &cli.command {
        Command::Analyze(args) => return cli::analyze::run(args),
        Command::Scenario(args) => cli::scenario::run(args)?,
        Command::Bench(args) => {
            cli::set_threads(args.threads)?;
            cli::bench::run(args)?;
        }
        Command::Verify(args) => return cli::verify::run(args),
        Command::Converge(args) => return cli::converge::run(args),
        Command::Report(args) => cli::report::run(args)?,
    }
    Ok(ExitCode::SUCCESS)
}

/// A reader that went away (`kneeform ... | head`) is not an error.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
