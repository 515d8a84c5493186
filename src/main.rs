//! The `mbd` command line: parses the arguments and runs the subcommand (`src/cli/`).
//! Exit codes: 0 success; 1 the model has errors; 2 bad command-line usage; 3 the simulation
//! failed at run time (the CSV keeps every row computed before the failure).

mod cli;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "mbd",
    version,
    about = "Compile and simulate .mbd flexible multibody models"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a model and write its output channels as CSV.
    Run(cli::run::RunArgs),
    /// Natural frequencies and mode shapes about the initial state, as CSV; with --sweep, a
    /// fan plot against a param.
    #[command(long_about = cli::modes::LONG_ABOUT)]
    Modes(cli::modes::ModesArgs),
    /// Check a model and print a summary, or one stage of the compilation.
    Check(cli::check::CheckArgs),
    /// Time histories of channels of a run's CSV, as an SVG chart.
    Plot(cli::plot::PlotArgs),
    /// Convergence or stability study: many runs of a model, one channel measured.
    #[command(long_about = cli::study::LONG_ABOUT)]
    Study(cli::study::StudyArgs),
    /// Stability sweep: characteristic exponents (Floquet, Prony) against a param.
    #[command(long_about = cli::stability::LONG_ABOUT)]
    Stability(cli::stability::StabilityArgs),
    /// Join the shares of a stability sweep (`mbd stability --shard K/N`) into its CSV and chart.
    #[command(long_about = cli::merge::LONG_ABOUT)]
    Merge(cli::merge::MergeArgs),
    /// The model in 3-D at t = 0: one HTML file that opens offline, or a glTF binary.
    #[command(long_about = cli::view::LONG_ABOUT)]
    View(cli::view::ViewArgs),
    /// Explain a diagnostic code, e.g. `mbd explain E0202`.
    Explain { code: String },
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { cli::EXIT_USAGE } else { 0 });
        }
    };
    // Ctrl-C: runs stop after their step, keeping their rows; a second one ends at once.
    let _ = ctrlc::set_handler(|| {
        if mbd::solve::interrupted() {
            std::process::exit(cli::EXIT_INTERRUPTED.into());
        }
        mbd::solve::interrupt();
    });
    let code = match cli.command {
        Command::Run(args) => cli::run::run(args),
        Command::Modes(args) => cli::modes::modes(args),
        Command::Check(args) => cli::check::check(args),
        Command::Plot(args) => cli::plot::plot(args),
        Command::Study(args) => cli::study::study(args),
        Command::Stability(args) => cli::stability::stability(args),
        Command::Merge(args) => cli::merge::merge(args),
        Command::View(args) => cli::view::view(args),
        Command::Explain { code } => cli::explain::explain(&code),
    };
    if mbd::solve::interrupted() {
        return ExitCode::from(cli::EXIT_INTERRUPTED);
    }
    code
}
