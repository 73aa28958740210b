//! The `kneeform` command line: parses flags, runs one command, prints one
//! clear line on error (exit 2) and never a backtrace.

mod cli;

use std::process::ExitCode;

use clap::Parser;
use clap::error::ErrorKind;

use cli::args::{Cli, Command};

/// Exit code after SIGINT or SIGTERM (128 + SIGINT's number, as shells
/// report an interrupted command).
const INTERRUPTED: i32 = 130;

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) => return flag_error(&err),
    };
    // An interrupted run leaves nothing behind: its staged results and
    // temporary files are removed (a commit in progress finishes first).
    let handler = ctrlc::set_handler(|| {
        use kneeform::output::Interrupted;
        // A batch's running item ends first: its lock must not outlive
        // the batch (an immediate resume was refused by it).
        cli::batch::end_running_child();
        // What is true when the signal came: a merge interrupted in its
        // final commit has written its result whole.
        eprintln!(
            "kneeform: interrupted; {}",
            match kneeform::output::remove_staged() {
                Interrupted::PartialRemoved => "partial results removed",
                Interrupted::AfterCommit => "its results were already written whole",
                Interrupted::BeforeAnyResult => "nothing was written",
            }
        );
        std::process::exit(INTERRUPTED);
    });
    if let Err(err) = handler {
        eprintln!(
            "kneeform: warning: cannot catch interrupts ({err}); an interrupted run may leave a hidden .partial directory"
        );
    }
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
    if let Some((need, room)) = kneeform::memory::short_to_start() {
        anyhow::bail!(
            "kneeform needs about {:.2} GiB of address space to start (the program, and an allocator arena for each thread), more than the {:.2} GiB the system gives it now (ulimit -v, or its overcommit limit)",
            need / GIB,
            room / GIB
        );
    }
    match &cli.command {
        Command::Analyze(args) => return cli::analyze::run(args),
        Command::Scenario(args) => cli::scenario::run(args)?,
        Command::Bench(args) => {
            cli::set_threads(args.threads)?;
            cli::bench::run(args)?;
        }
        Command::Verify(args) => return cli::verify::run(args),
        Command::Converge(args) => return cli::converge::run(args),
        Command::Merge(args) => return cli::merge::run(args),
        Command::Batch(args) => return cli::batch::run(args),
        Command::Report(args) => cli::report::run(args)?,
        Command::Diff(args) => cli::diff::run(args)?,
    }
    Ok(ExitCode::SUCCESS)
}

/// What clap found wrong with the command line, as every error is said:
/// one line, exit 2 (clap's own is its message, a usage and a tip, on
/// several). Help and the version are printed as clap prints them.
fn flag_error(err: &clap::Error) -> ExitCode {
    if matches!(
        err.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        let _ = err.print();
        return if err.use_stderr() {
            ExitCode::from(2)
        } else {
            ExitCode::SUCCESS
        };
    }
    let first = cli::clap_message(err);
    eprintln!("kneeform: error: {first} (`kneeform help COMMAND` lists its flags)");
    ExitCode::from(2)
}

/// A reader that went away (`kneeform ... | head`) is not an error.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
