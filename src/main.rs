//! The `plc-deps` command line: parses arguments into validated configurations and calls the
//! library (`plc_deps::app`). Nothing else happens here.

// mimalloc: the analyses allocate many small vectors right after the loader frees a large JSON
// tree; glibc's malloc spends seconds consolidating that heap at 1M rungs, mimalloc does not.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

use clap::{Parser, Subcommand, ValueEnum};
use plc_deps::app::{self, CliError, ReportConfig, ReportFormat};
use plc_deps::report::View;
use std::path::PathBuf;
use std::process::ExitCode;

/// Dependence analysis, levelling and multicore scan of IEC 61131-3 ladder programs.
#[derive(Parser)]
#[command(name = "plc-deps", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Analyse a program: dependences, control flow, post-dominators, levels, cycles, cost.
    Report {
        /// The program (JSON program format, see docs/format.md).
        file: PathBuf,
        /// Output format.
        #[arg(long, value_enum, default_value_t = FormatArg::Text)]
        format: FormatArg,
        /// Which levellings the text and DOT outputs show (JSON always has all of them).
        #[arg(long, value_enum, default_value_t = ViewArg::All)]
        view: ViewArg,
        /// Write to this file instead of standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Print the JSON Schema of the program format.
    Schema {
        /// Write to this file instead of standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Generate a synthetic program (shape documented in docs/gen.md).
    Gen {
        /// Number of rungs of the main program.
        #[arg(long)]
        rungs: usize,
        /// Rungs per stage: the program has about rungs / width data levels.
        #[arg(long, default_value_t = 100)]
        width: usize,
        /// Seed of the pseudo-random choices (same seed, same program).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Add timers (TON boxes and reads of their Q).
        #[arg(long)]
        timers: bool,
        /// Add FOR/NEXT loops.
        #[arg(long)]
        loops: bool,
        /// Add conditional forward jumps.
        #[arg(long)]
        jumps: bool,
        /// Add subroutines and calls.
        #[arg(long)]
        calls: bool,
        /// Write to this file instead of standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
}

#[derive(Copy, Clone, ValueEnum)]
enum FormatArg {
    Text,
    Json,
    Dot,
}

#[derive(Copy, Clone, ValueEnum)]
enum ViewArg {
    Paper,
    Combined,
    All,
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Report { file, format, view, output } => {
            let config = ReportConfig {
                input: file,
                format: match format {
                    FormatArg::Text => ReportFormat::Text,
                    FormatArg::Json => ReportFormat::Json,
                    FormatArg::Dot => ReportFormat::Dot,
                },
                view: match view {
                    ViewArg::Paper => View::Paper,
                    ViewArg::Combined => View::Combined,
                    ViewArg::All => View::All,
                },
                output,
            };
            app::report(&config)
        }
        Command::Schema { output } => app::write_output(output.as_deref(), app::PROGRAM_SCHEMA),
        Command::Gen { rungs, width, seed, timers, loops, jumps, calls, output } => {
            if rungs == 0 || width == 0 {
                return Err(CliError::Usage("--rungs and --width must be at least 1".into()));
            }
            let config = plc_deps::gen::GenConfig { rungs, width, seed, timers, loops, jumps, calls };
            app::write_output_with(output.as_deref(), |w| plc_deps::gen::write_program(&config, w))
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
