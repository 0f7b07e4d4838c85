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
        /// The program (JSON program format, see docs/format.md; `-`: standard input).
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
    /// Print each FBD network's execution order and conditional fragment tree (seed 000).
    Order {
        /// The program (JSON program format with FBD bodies, see docs/fbd.md; `-`: standard
        /// input).
        file: PathBuf,
        /// Output format.
        #[arg(long, value_enum, default_value_t = FormatArg::Text)]
        format: FormatArg,
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
    /// Run the PLC scan cycle on virtual time: sequentially, in parallel, or both (checked equal).
    Run {
        /// The program (JSON program format, see docs/format.md; `-`: standard input).
        file: PathBuf,
        /// Number of scans [default: the rows of --inputs, or 1000].
        #[arg(long)]
        scans: Option<u64>,
        /// Input values per scan: CSV (header of input names, one row per scan) or JSON
        /// (`[{"start": true, "temp": 40}, ...]`); see docs/scan.md.
        #[arg(long)]
        inputs: Option<PathBuf>,
        /// Virtual scan period, a TIME of whole milliseconds (scan k runs at k × cycle).
        #[arg(long, default_value = "10ms")]
        cycle: String,
        /// Workers of the parallel executor [default: the number of cores].
        #[arg(long)]
        threads: Option<usize>,
        /// Which executors run.
        #[arg(long, value_enum, default_value_t = ModeArg::Both)]
        mode: ModeArg,
        /// Write the traced variables after every scan to this CSV file (checked before the
        /// first scan, complete or not at all).
        #[arg(long)]
        trace: Option<PathBuf>,
        /// Variables to trace with --trace (comma-separated; instance fields as T1.Q; each
        /// column once) [default: all].
        #[arg(long, value_delimiter = ',')]
        trace_vars: Option<Vec<String>>,
        /// Output format.
        #[arg(long, value_enum, default_value_t = RunFormatArg::Text)]
        format: RunFormatArg,
        /// Explain the parallel plan: levels, costs, slices, merges and padding.
        #[arg(long)]
        explain: bool,
        /// Loop-backs allowed per loop-back rung and scan (the iteration cap).
        #[arg(long, default_value_t = 100_000)]
        loop_cap: u32,
        /// Write the report to this file instead of standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
}

#[derive(Copy, Clone, ValueEnum)]
enum ModeArg {
    Seq,
    Par,
    Both,
}

#[derive(Copy, Clone, ValueEnum)]
enum RunFormatArg {
    Text,
    Json,
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
        Command::Report {
            file,
            format,
            view,
            output,
        } => {
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
        Command::Order {
            file,
            format,
            output,
        } => {
            let format = match format {
                FormatArg::Text => app::OrderFormat::Text,
                FormatArg::Json => app::OrderFormat::Json,
                FormatArg::Dot => app::OrderFormat::Dot,
            };
            app::order(&app::OrderConfig {
                input: file,
                format,
                output,
            })
        }
        Command::Schema { output } => app::write_output(output.as_deref(), app::PROGRAM_SCHEMA),
        Command::Gen {
            rungs,
            width,
            seed,
            timers,
            loops,
            jumps,
            calls,
            output,
        } => {
            if rungs == 0 || width == 0 {
                return Err(CliError::Usage(
                    "--rungs and --width must be at least 1".into(),
                ));
            }
            let config = plc_deps::gen::GenConfig {
                rungs,
                width,
                seed,
                timers,
                loops,
                jumps,
                calls,
            };
            app::write_output_with(output.as_deref(), |w| {
                plc_deps::gen::write_program(&config, w)
            })
        }
        Command::Run {
            file,
            scans,
            inputs,
            cycle,
            threads,
            mode,
            trace,
            trace_vars,
            format,
            explain,
            loop_cap,
            output,
        } => {
            use plc_deps::runcmd::{self, RunConfig, RunFormat, RunMode};
            let mut config = RunConfig::new(file);
            config.scans = scans;
            config.inputs = inputs;
            config.cycle_ms = runcmd::parse_cycle(&cycle)?;
            if let Some(t) = threads {
                config.threads = t;
            }
            config.mode = match mode {
                ModeArg::Seq => RunMode::Seq,
                ModeArg::Par => RunMode::Par,
                ModeArg::Both => RunMode::Both,
            };
            config.trace = trace;
            config.trace_vars = trace_vars;
            config.format = match format {
                RunFormatArg::Text => RunFormat::Text,
                RunFormatArg::Json => RunFormat::Json,
            };
            config.explain = explain;
            config.loop_cap = loop_cap;
            config.output = output;
            runcmd::run(&config)
        }
    }
}

/// On SIGINT or SIGTERM: remove the temporary files being written (an output or trace file in
/// the making) and exit with 130, so a stopped command leaves nothing behind.
fn remove_temp_files_on_signal() {
    let _ = ctrlc::set_handler(|| {
        app::remove_temp_files();
        use std::io::{IsTerminal, Write};
        if std::io::stderr().is_terminal() {
            // Clear a progress line, so the shell's prompt starts on a clean line.
            let _ = write!(std::io::stderr(), "\r\x1b[2K");
        }
        std::process::exit(130);
    });
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    remove_temp_files_on_signal();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
