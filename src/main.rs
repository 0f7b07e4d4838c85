//! The `plc-deps` command line: parses arguments into validated configurations and calls the
//! library (`plc_deps::cmd`). Nothing else happens here.
#![forbid(unsafe_code)]

// mimalloc: the analyses allocate many small vectors right after the loader frees a large JSON
// tree; glibc's malloc spends seconds consolidating that heap at 1M rungs, mimalloc does not.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

use clap::{Args, Parser, Subcommand};
use plc_deps::analysis::{AnalysisConfig, DependenceListing};
use plc_deps::cmd::order::OrderFormat;
use plc_deps::cmd::report::{ReportConfig, ReportFormat};
use plc_deps::cmd::run::{RunFormat, RunMode};
use plc_deps::cmd::{self, CliError};
use plc_deps::exec::parallel::PlanKind;
use plc_deps::report::{Rows, Selection, View};
use plc_deps::synth::Reads;
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
    Report(ReportArgs),
    /// Print each FBD network's execution order and conditional fragment tree (the FBD text-generation paper).
    Order {
        /// The program (JSON program format with FBD bodies, see docs/fbd.md; `-`: standard
        /// input).
        file: PathBuf,
        /// Output format.
        #[arg(long, value_enum, default_value_t = OrderFormat::Text)]
        format: OrderFormat,
        /// The configuration of a PLCopen project with several (IEC 61131-3: each a controller
        /// of its own) to read [default: the first in the file, with a warning W0502 naming the
        /// others].
        #[arg(long, value_name = "NAME")]
        configuration: Option<String>,
        /// Write to this file instead of standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Write a program file (PLCopen TC6 XML, or JSON) as the JSON program format: what
    /// plc-deps understood of it (docs/format.md).
    Convert {
        /// The program (S7-200 STL, PLCopen TC6 XML or the JSON program format; `-`: standard
        /// input).
        file: PathBuf,
        /// Write the JSON even when a POU's body is not executed (a PLCopen ST, IL or SFC
        /// body, read only as stand-in rungs): the JSON holds the stand-ins as ordinary rungs.
        /// Without it, such a POU is an error.
        #[arg(long)]
        allow_skipped: bool,
        /// The configuration of a PLCopen project with several (IEC 61131-3: each a controller
        /// of its own) to read [default: the first in the file, with a warning W0502 naming the
        /// others].
        #[arg(long, value_name = "NAME")]
        configuration: Option<String>,
        /// Write to this file instead of standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Generate C for every POU, a runtime header, main.c and a Makefile (docs/c.md).
    C(CArgs),
    /// Write the program as S7-200 Instruction List (STL), as STEP 7-Micro/WIN shows it (docs/il.md).
    Il {
        /// The program (JSON program format, PLCopen XML or STL; `-`: standard input).
        file: PathBuf,
        /// The configuration of a PLCopen project with several (IEC 61131-3: each a controller
        /// of its own) to read [default: the first in the file, with a warning W0502 naming the
        /// others].
        #[arg(long, value_name = "NAME")]
        configuration: Option<String>,
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
    Gen(GenArgs),
    /// Run the PLC scan cycle on virtual time: sequentially, in parallel, or both (checked equal).
    Run(RunArgs),
}

#[derive(Args)]
struct ReportArgs {
    /// The program (JSON program format, see docs/format.md; `-`: standard input).
    file: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value_t = ReportFormat::Text)]
    format: ReportFormat,
    /// Which levellings the output shows (JSON and HTML always have all of them) [default:
    /// all for text, combined for DOT, which draws one levelling].
    #[arg(long, value_enum)]
    view: Option<View>,
    /// Print every row of every text section (by default each shows its first rows).
    #[arg(long)]
    full: bool,
    /// Which data dependences are listed: every pair of the definition, or only the direct
    /// ones (last writer → reader, reader → next writer, writer → next writer), which imply
    /// the rest [default: all up to --max-pairs, direct beyond].
    #[arg(long, value_enum)]
    dependences: Option<DependenceListing>,
    /// The most data dependence pairs listed before the report lists the direct ones instead.
    #[arg(long, default_value_t = plc_deps::analysis::DEFAULT_MAX_PAIRS)]
    max_pairs: u64,
    /// DOT: draw the rungs of this POU (the program, a subroutine or an FB instance). Text,
    /// JSON, HTML: analyse only this program of a PLCopen project or a configuration, or, in a
    /// program without a configuration, this subroutine and what it calls [default: every
    /// program instance, in task order].
    #[arg(long, conflicts_with = "rungs")]
    pou: Option<String>,
    /// DOT only: draw the rungs from FIRST to LAST in file order (`R10..R50`, or one id).
    #[arg(long, value_name = "FIRST..LAST")]
    rungs: Option<String>,
    /// The configuration of a PLCopen project with several (IEC 61131-3: each a controller
    /// of its own) to read [default: the first in the file, with a warning W0502 naming the
    /// others].
    #[arg(long, value_name = "NAME")]
    configuration: Option<String>,
    /// Write to this file instead of standard output.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

#[derive(Args)]
struct GenArgs {
    /// Number of rungs of the main program (at least 1).
    #[arg(long)]
    rungs: usize,
    /// Rungs per stage: the program has about rungs / width data levels.
    #[arg(long, default_value_t = 100, conflicts_with = "levels")]
    width: usize,
    /// Data levels instead of --width: width = ceil(rungs / levels) (at least 1).
    #[arg(long, value_name = "L")]
    levels: Option<usize>,
    /// Which lanes of the previous stage a rung reads: 3-5 nearby ones (local) or 3-6 drawn
    /// at random from the whole stage (random).
    #[arg(long, value_enum, default_value_t = Reads::Local)]
    reads: Reads,
    /// Seed of the pseudo-random choices (same seed, same program).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Add timer boxes (TON, TOF, TP), counter boxes (CTU, CTD), and reads of their Q and of
    /// the counters' CV.
    #[arg(long)]
    timers: bool,
    /// Add FOR/NEXT loops (about 1 in 200 rungs starts one).
    #[arg(long)]
    loops: bool,
    /// With --loops: every FOR body has exactly N rungs (at least 1), and the first loop
    /// starts as early as it fits (default: 2 to 4 body rungs).
    #[arg(long, value_name = "N", requires = "loops")]
    for_body: Option<usize>,
    /// A hot variable: about F * rungs main rungs (0 < F <= 1) also set the BOOL FAULT and
    /// a tenth as many read it, spread evenly over the program.
    #[arg(long, value_name = "F")]
    hot_fraction: Option<f64>,
    /// Add conditional forward jumps.
    #[arg(long)]
    jumps: bool,
    /// Add subroutines and calls.
    #[arg(long)]
    calls: bool,
    /// Write to this file instead of standard output.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

#[derive(Args)]
struct RunArgs {
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
    #[arg(long, value_enum, default_value_t = RunMode::Both)]
    mode: RunMode,
    /// Write the traced variables after every scan to this CSV file (checked before the
    /// first scan, complete or not at all).
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Variables to trace with --trace (comma-separated; instance fields as T1.Q; each
    /// column once) [default: all].
    #[arg(long, value_delimiter = ',')]
    trace_vars: Option<Vec<String>>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = RunFormat::Text)]
    format: RunFormat,
    /// Explain the parallel plan: levels, costs, slices, merges and padding, and what the
    /// run chose (measured times, switches).
    #[arg(long)]
    explain: bool,
    /// Which plans the parallel executor may use: measured among the sequential walk and
    /// the levelled plans (auto), the cost model's choice (model), always the sequential
    /// walk (seq), always the levelled plan (par), always the dependence-driven plan (deps:
    /// ready flags instead of a barrier per level), always the levelled plan on private
    /// states handing over packed writes after each phase (exchange).
    #[arg(long, value_enum, default_value_t = PlanKind::Auto)]
    plan: PlanKind,
    /// Loop-backs allowed per loop-back rung and scan (the iteration cap).
    #[arg(long, default_value_t = 100_000)]
    loop_cap: u32,
    /// Rungs each task of a scan (a main-program rung or loop, with what it calls) may
    /// charge with its calls and loop-backs before they are refused with a scan-budget fault
    /// (docs/scan.md).
    #[arg(long, value_name = "N", default_value_t = plc_deps::exec::DEFAULT_SCAN_BUDGET)]
    scan_budget: u64,
    /// With --mode both, the scans of each mode's turn: the two passes alternate in blocks
    /// of this many scans, so that a change of the machine's speed hits both [default:
    /// about 20 ms of the sequential walk's scans, and at least a 64th of the run].
    #[arg(long, value_name = "N")]
    alternate: Option<u64>,
    /// Run only this program of a PLCopen project or a configuration, or, in a program
    /// without a configuration, this subroutine and what it calls [default: every program
    /// instance, in task order].
    #[arg(long)]
    pou: Option<String>,
    /// The configuration of a PLCopen project with several (IEC 61131-3: each a controller
    /// of its own) to read [default: the first in the file, with a warning W0502 naming the
    /// others].
    #[arg(long, value_name = "NAME")]
    configuration: Option<String>,
    /// Go on when a POU's body is not executed (a PLCopen ST, IL or SFC body, read only as
    /// stand-in rungs that keep every value): the output lists those POUs. Without it, such
    /// a POU is an error.
    #[arg(long)]
    allow_skipped: bool,
    /// Whose rules to follow where toolchains differ (counters, timers, TIME conversions;
    /// docs/dialects.md): iec, matiec or codesys [default: a PLCopen file's editor's (CODESYS
    /// and TwinCAT: codesys, any other: matiec); iec for JSON and STL].
    #[arg(long, value_parser = parse_dialect)]
    dialect: Option<plc_deps::model::Dialect>,
    /// Write the report to this file instead of standard output.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

#[derive(Args)]
struct CArgs {
    /// The program (JSON program format; `-`: standard input).
    file: PathBuf,
    /// The folder to write (all files or none).
    #[arg(short, long)]
    output: PathBuf,
    /// Replace an existing folder that is not empty.
    #[arg(long)]
    force: bool,
    /// The scan cycle of the harness (a TIME: 10ms, T#1s).
    #[arg(long, default_value = "10ms")]
    cycle: String,
    /// Loop-backs per loop-back rung and scan.
    #[arg(long, default_value_t = 100_000)]
    loop_cap: u32,
    /// Rungs each task of a scan may charge with its calls and loop-backs (as `run
    /// --scan-budget`; the generated C's PLC_SCAN_BUDGET).
    #[arg(long, value_name = "N", default_value_t = plc_deps::exec::DEFAULT_SCAN_BUDGET)]
    scan_budget: u64,
    /// Write every rung as C statements, not the rungs of contacts and coils as rows of
    /// tables run by loops specialised by shape (the default; docs/c.md): `cc` takes about
    /// 1 ms of CPU per rung written as statements, minutes at 100,000 rungs.
    #[arg(long)]
    statements: bool,
    /// Worker threads of the parallel scan (N ≥ 1): 1 writes the sequential program only;
    /// N ≥ 2 adds `plc_scan_parallel`, the adaptive scan and the runtime API (plc_api.h;
    /// docs/c.md), the interpreter's parallel plan written as C on N pthreads.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u16).range(1..))]
    threads: u16,
    /// With --threads: every level of the schedule a parallel phase, whatever the cost model
    /// says (for tests and measurements).
    #[arg(long, hide = true)]
    parallel_all: bool,
    /// Go on when a POU's body is not executed (a PLCopen ST, IL or SFC body, read only as
    /// stand-in rungs that keep every value): the output lists those POUs. Without it, such
    /// a POU is an error.
    #[arg(long)]
    allow_skipped: bool,
    /// Whose rules to follow where toolchains differ, as `run --dialect` (docs/dialects.md).
    #[arg(long, value_parser = parse_dialect)]
    dialect: Option<plc_deps::model::Dialect>,
    /// The configuration of a PLCopen project with several (IEC 61131-3: each a controller
    /// of its own) to read [default: the first in the file, with a warning W0502 naming the
    /// others].
    #[arg(long, value_name = "NAME")]
    configuration: Option<String>,
    /// Accepted for compatibility: rows are the default.
    #[arg(long, hide = true)]
    rows: bool,
}

/// `--dialect NAME`.
fn parse_dialect(name: &str) -> Result<plc_deps::model::Dialect, String> {
    plc_deps::model::Dialect::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = plc_deps::model::Dialect::ALL
            .iter()
            .map(|d| d.name())
            .collect();
        format!("`{name}` is not a dialect ({})", names.join(", "))
    })
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Report(args) => cmd::report::report(&args.config()?),
        Command::Order {
            file,
            format,
            configuration,
            output,
        } => cmd::order::order(&cmd::order::OrderConfig {
            input: file,
            format,
            configuration,
            output,
        }),
        Command::Convert {
            file,
            allow_skipped,
            configuration,
            output,
        } => cmd::convert::convert(&cmd::convert::ConvertConfig {
            input: file,
            allow_skipped,
            configuration,
            output,
        }),
        Command::C(args) => cmd::c::c(&args.command()?),
        Command::Il {
            file,
            configuration,
            output,
        } => cmd::il::il(&cmd::il::IlCommand {
            input: file,
            configuration,
            output,
        }),
        Command::Schema { output } => {
            cmd::io::write_output(output.as_deref(), cmd::schema::PROGRAM_SCHEMA)
        }
        Command::Gen(args) => cmd::gen::gen(&args.command()),
        Command::Run(args) => plc_deps::cmd::run::run(&args.config()?),
    }
}

impl ReportArgs {
    /// The report's configuration; a usage error for options that do not go together.
    fn config(self) -> Result<ReportConfig, CliError> {
        let format = self.format;
        // Outside DOT, --pou selects the PLCopen program to analyse.
        let (pou, program) = match format {
            ReportFormat::Dot => (self.pou, None),
            _ => (None, self.pou),
        };
        let selection = match (pou, self.rungs) {
            (Some(name), _) => Selection::Pou(name),
            (None, Some(range)) => match range.split_once("..") {
                Some((first, last)) => Selection::Rungs {
                    first: first.trim().to_owned(),
                    last: last.trim().to_owned(),
                },
                None => Selection::Rungs {
                    first: range.trim().to_owned(),
                    last: range.trim().to_owned(),
                },
            },
            (None, None) => Selection::Whole,
        };
        if selection != Selection::Whole && format != ReportFormat::Dot {
            return Err(CliError::Usage(
                "--rungs chooses what the DOT report draws; add --format dot (the text and JSON reports cover the whole program)".into(),
            ));
        }
        let view = match (self.view, format) {
            (Some(View::Paper), _) => View::Paper,
            (Some(View::Combined), _) | (None, ReportFormat::Dot) => View::Combined,
            (Some(View::All), ReportFormat::Dot) => {
                return Err(CliError::Usage(
                    "--view all: the DOT report draws one levelling; use --view combined (the default) or --view paper".into(),
                ))
            }
            (Some(View::All), _) | (None, _) => View::All,
        };
        Ok(ReportConfig {
            input: self.file,
            format,
            view,
            rows: if self.full {
                Rows::All
            } else {
                Rows::First(plc_deps::report::text::DEFAULT_ROWS)
            },
            analysis: AnalysisConfig {
                dependences: self
                    .dependences
                    .unwrap_or(DependenceListing::UpTo(self.max_pairs)),
            },
            selection,
            program,
            configuration: self.configuration,
            output: self.output,
        })
    }
}

impl CArgs {
    /// The C generator's command; a usage error for a cycle that is not a TIME.
    fn command(self) -> Result<cmd::c::CCommand, CliError> {
        Ok(cmd::c::CCommand {
            input: self.file,
            output: self.output,
            force: self.force,
            allow_skipped: self.allow_skipped,
            dialect: self.dialect,
            configuration: self.configuration,
            config: plc_deps::codegen::c::CConfig {
                cycle_ms: cmd::run::parse_cycle(&self.cycle)?,
                loop_cap: self.loop_cap,
                scan_budget: self.scan_budget,
                rows: !self.statements,
                threads: usize::from(self.threads),
                parallel_all: self.parallel_all,
                ..Default::default()
            },
        })
    }
}

impl GenArgs {
    /// The generator's command.
    fn command(self) -> cmd::gen::GenCommand {
        cmd::gen::GenCommand {
            config: plc_deps::synth::GenConfig {
                rungs: self.rungs,
                width: self.width,
                seed: self.seed,
                timers: self.timers,
                loops: self.loops,
                jumps: self.jumps,
                calls: self.calls,
                for_body: self.for_body,
                hot_fraction: self.hot_fraction,
                reads: self.reads,
            },
            levels: self.levels,
            output: self.output,
        }
    }
}

impl RunArgs {
    /// The run's configuration; a usage error for a cycle that is not a TIME.
    fn config(self) -> Result<plc_deps::cmd::run::RunConfig, CliError> {
        use plc_deps::cmd::run::{self, RunConfig};
        let mut config = RunConfig::new(self.file);
        config.scans = self.scans;
        config.alternate = self.alternate;
        config.inputs = self.inputs;
        config.cycle_ms = run::parse_cycle(&self.cycle)?;
        if let Some(t) = self.threads {
            config.threads = t;
        }
        config.mode = self.mode;
        config.trace = self.trace;
        config.trace_vars = self.trace_vars;
        config.format = self.format;
        config.explain = self.explain;
        config.plan = self.plan;
        config.loop_cap = self.loop_cap;
        config.scan_budget = self.scan_budget;
        config.output = self.output;
        config.program = self.pou;
        config.configuration = self.configuration;
        config.allow_skipped = self.allow_skipped;
        config.dialect = self.dialect;
        Ok(config)
    }
}

/// On SIGINT or SIGTERM: remove the temporary files being written (an output or trace file in
/// the making) and exit with 130, so a stopped command leaves nothing behind.
fn remove_temp_files_on_signal() {
    let _ = ctrlc::set_handler(|| {
        cmd::io::remove_temp_files();
        use std::io::{IsTerminal, Write};
        if std::io::stderr().is_terminal() {
            // Clear a progress line, so the shell's prompt starts on a clean line.
            let _ = write!(std::io::stderr(), "\r\x1b[2K");
        }
        std::process::exit(130);
    });
}

/// The command line, or the exit code once `--help` or `--version` has been printed. Printed to
/// a terminal by clap itself (in colour); to anything else through `cmd::io::write_stream`, so
/// that a failed write is an error (exit code 2) and not ignored as clap does. Usage errors are
/// clap's (standard error, exit code 2).
fn parse_cli() -> Result<Cli, ExitCode> {
    use std::io::IsTerminal;
    match Cli::try_parse() {
        Ok(cli) => Ok(cli),
        Err(e) if !e.use_stderr() && !std::io::stdout().is_terminal() => {
            let text = e.render().to_string();
            match cmd::io::write_stream(cmd::io::Stream::Stdout, |w| w.write_all(text.as_bytes())) {
                Ok(()) => Err(ExitCode::SUCCESS),
                Err(err) => {
                    cmd::errors::print_error(&err);
                    Err(ExitCode::from(err.exit_code()))
                }
            }
        }
        Err(e) => e.exit(),
    }
}

/// How errors and warnings are printed: as JSON lines when the command was given `--format json`.
fn error_format(cli: &Cli) -> cmd::errors::Format {
    let json = match &cli.command {
        Command::Report(args) => args.format == ReportFormat::Json,
        Command::Order { format, .. } => *format == OrderFormat::Json,
        Command::Run(args) => args.format == RunFormat::Json,
        _ => false,
    };
    if json {
        cmd::errors::Format::Json
    } else {
        cmd::errors::Format::Text
    }
}

/// Exit codes (README, docs/diagnostics.md): 0 done, 1 a run that faulted or whose modes
/// differed, 2 bad input or usage (clap's usage errors are 2 too), 130 stopped by a signal.
fn main() -> ExitCode {
    cmd::pages::prefer_small_pages();
    let cli = match parse_cli() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    cmd::errors::set_format(error_format(&cli));
    remove_temp_files_on_signal();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            cmd::errors::print_error(&e);
            ExitCode::from(e.exit_code())
        }
    }
}
