//! `plc-deps report`: load, analyse, build the report document, render it (text, JSON, DOT or HTML)
//! to standard output or atomically to `-o`. Warnings (coded `W02xx`, docs/diagnostics.md) go to
//! standard error, as diagnostics in the command's format, as well as into the report. Long
//! phases show progress on a terminal.

use super::io::{
    check_output_path, load_text_selecting, read_program_text, write_output_with, FileRole, Pick,
};
use super::progress::Progress;
use super::CliError;
use plc_analysis::{analyse, analyse_with, Analysis, AnalysisConfig, DependenceListing, Listed};
use plc_diag::{Origin, Severity, Shown};
use plc_fbd::Fbd;
use plc_model::Program;
use plc_report::{
    document_with, fbd_parts, render_dot, render_html, render_json, render_text, select_rungs,
    warning_code, warning_origin, warning_text, FbdParts, HtmlInput, Rows, Selection, TextOptions,
    View, DIRECT_PAIRS_ONLY, DOT_MAX_RUNGS,
};
use std::collections::HashSet;
use std::path::PathBuf;

/// Output format of `report` (`--format`: the variants are the command line's values, a
/// variant's doc comment its help).
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ReportFormat {
    Text,
    Json,
    Dot,
    /// One self-contained page (docs/html.md).
    Html,
}

/// A validated `plc-deps report` invocation.
#[derive(Clone, Debug)]
pub struct ReportConfig {
    pub input: PathBuf,
    pub format: ReportFormat,
    /// The levellings text and DOT show.
    pub view: View,
    /// Rows per section of the text report.
    pub rows: Rows,
    /// Which data dependences are listed.
    pub analysis: AnalysisConfig,
    /// The rungs the DOT report draws (only `Selection::Whole` for text, JSON and HTML).
    pub selection: Selection,
    /// The program of a PLCopen project to analyse (`--pou` with the text, JSON and HTML
    /// reports); `None`: every program instance, in task order.
    pub program: Option<String>,
    /// The configuration of a PLCopen project with several (`--configuration`); `None`: the
    /// first in file order.
    pub configuration: Option<String>,
    pub output: Option<PathBuf>,
}

/// Writes the report of `p` (with `fbd`, what its FBD lowering made) in `format`; the DOT report
/// draws only the rungs in `drawn` when it is given. (The HTML report draws FBD blocks as their
/// lowered rungs here: [`write_report_with`] gives it the FBD bodies.)
pub fn write_report(
    p: &Program,
    a: &Analysis,
    fbd: Option<&FbdParts>,
    format: ReportFormat,
    text: &TextOptions,
    drawn: Option<&HashSet<String>>,
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    write_report_with(p, a, None, fbd, format, text, drawn, out)
}

/// [`write_report`] with the FBD bodies as written (`bodies`), which the HTML report draws.
#[allow(clippy::too_many_arguments)]
pub fn write_report_with(
    p: &Program,
    a: &Analysis,
    bodies: Option<&Fbd>,
    fbd: Option<&FbdParts>,
    format: ReportFormat,
    text: &TextOptions,
    drawn: Option<&HashSet<String>>,
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    let doc = document_with(p, a, fbd);
    // The renderers make many small writes: a buffer of a known type here keeps each of them a
    // copy into memory, whatever `out` is (a `dyn Write` file costs a call per write); 64 KB
    // stays in the core's cache on its way on.
    let mut out = std::io::BufWriter::with_capacity(1 << 16, out);
    match format {
        ReportFormat::Text => render_text(&doc, text, &mut out),
        ReportFormat::Json => render_json(&doc, &mut out),
        ReportFormat::Dot => render_dot(&doc, text.view, drawn, &mut out),
        ReportFormat::Html => render_html(
            &HtmlInput {
                doc: &doc,
                program: p,
                analysis: a,
                fbd: bodies,
            },
            &mut out,
        ),
    }?;
    std::io::Write::flush(&mut out)
}

/// Renders the report of a loaded program and its FBD bodies with the default options (a
/// convenience for tests and small programs: the command streams instead).
pub fn render_report(p: &Program, fbd: &Fbd, format: ReportFormat, view: View) -> String {
    let a = analyse(p);
    let parts = fbd_parts(p, fbd);
    let mut out = Vec::new();
    let text = TextOptions {
        view,
        ..TextOptions::default()
    };
    write_report_with(
        p,
        &a,
        Some(fbd),
        parts.as_ref(),
        format,
        &text,
        None,
        &mut out,
    )
    .expect("writing to memory cannot fail");
    String::from_utf8(out).expect("reports are UTF-8")
}

/// `plc-deps report`. Warnings go to standard error as well as into the report.
pub fn report(c: &ReportConfig) -> Result<(), CliError> {
    if let Some(out) = &c.output {
        check_output_path(out, FileRole::Output)?;
    }
    let progress = Progress::stderr();
    let (file, source) = read_program_text(&c.input)?;
    let (p, fbd) = {
        let _phase = progress.phase("reading the program");
        load_text_selecting(
            file.clone(),
            &source,
            Pick {
                pou: c.program.as_deref(),
                configuration: c.configuration.as_deref(),
            },
        )?
    };
    // The text places the warnings, which are known only after the analysis. It is kept: a big
    // program file is mapped, not read (`SourceText`), so keeping it costs no memory of ours.
    let source: &str = &source;
    let parts = fbd_parts(&p, &fbd);
    let drawn = dot_selection(c, &p)?;
    let a = {
        let _phase = progress.phase("analysing");
        analyse_with(&p, &c.analysis)
    };
    let warn = |code: &'static str, message: String, origin: Origin| {
        let shown = if origin.is_none() {
            let mut shown = Shown::unplaced(Severity::Warning, code, message);
            shown.file = file.clone();
            shown
        } else {
            Shown::warning(code, message, &file, source, origin)
        };
        super::errors::warn(&shown);
    };
    for w in &a.warnings {
        warn(warning_code(w), warning_text(&p, w), warning_origin(&p, w));
    }
    if a.listed == Listed::Direct && c.analysis.dependences != DependenceListing::Direct {
        warn(DIRECT_PAIRS_ONLY, format!(
            "{} data dependence pairs are more than --max-pairs allows; listing the {} direct ones (they imply the rest; --dependences all lists every pair)",
            plc_report::text::thousands(a.counts.total() as usize),
            plc_report::text::thousands(a.data.len())
        ), Origin::NONE);
    }
    let text = TextOptions {
        view: c.view,
        rows: c.rows,
    };
    let _phase = progress.phase("writing the report");
    write_output_with(c.output.as_deref(), |w| {
        let mut w = w;
        write_report_with(
            &p,
            &a,
            Some(&fbd),
            parts.as_ref(),
            c.format,
            &text,
            drawn.as_ref(),
            &mut w,
        )
    })
}

/// The rungs the DOT report of `p` draws (`None`: all), refused above [`DOT_MAX_RUNGS`].
fn dot_selection(c: &ReportConfig, p: &Program) -> Result<Option<HashSet<String>>, CliError> {
    use plc_report::text::thousands;
    if c.format != ReportFormat::Dot {
        return Ok(None);
    }
    let drawn = select_rungs(p, &c.selection)
        .map_err(|e| CliError::Usage(format!("{}: {e}", c.input.display())))?;
    match &drawn {
        None if p.rungs().len() > DOT_MAX_RUNGS => Err(CliError::Usage(format!(
            "{}: {} rungs are too many to draw ({} at most): Graphviz cannot lay out a graph this size usefully; draw a part with --pou NAME or --rungs FIRST..LAST, or use the text or JSON report",
            c.input.display(),
            thousands(p.rungs().len()),
            thousands(DOT_MAX_RUNGS)
        ))),
        Some(s) if s.len() > DOT_MAX_RUNGS => Err(CliError::Usage(format!(
            "{}: the selection has {} rungs, too many to draw ({} at most); choose a shorter --rungs range",
            c.input.display(),
            thousands(s.len()),
            thousands(DOT_MAX_RUNGS)
        ))),
        _ => Ok(drawn),
    }
}
