//! PLCopen TC6 XML (the exchange format of IEC 61131-3 editors: Beremiz, OpenPLC Editor,
//! CODESYS) → the surface syntax ([`plc_syntax`]), so that resolution, checks, analysis and
//! execution are the JSON format's.
//!
//! The text is parsed by `roxmltree` (no DTD, so no entity expansion; at most
//! [`xml::MAX_XML_BYTES`]; nesting at most [`xml::MAX_DEPTH`]); the project must be in one of
//! the namespaces tc6_0201, tc6_0200 or the pre-2.0 tc6.xsd ([`xml::NAMESPACES`]), elements
//! are matched by local name. [`project`] reads the POUs and configurations, [`interface`] the
//! variable lists ([`data_types`] the data types and structures, a structure flattened into its fields), [`ld`] (with [`ld_power`], [`ld_block`], [`ld_logic`] and the shared [`wiring`] graph) the
//! LD bodies ([`ld_flow`]: those that are not series-parallel rungs, as Beremiz's data-flow
//! network), [`fbd`] the FBD bodies ([`black_box`]: conversions and blocks the model lacks; [`expression`]: in variables' expressions), [`st_body`] the ST bodies (a stand-in rung per statement,
//! from the ST parser, for the analyses; [`st_lower`]: the rungs `run` and `c` execute), [`il_body`] the IL bodies ([`il_parse`]; translated to ST and lowered for `run` and `c`, analysed through their interface), [`textual`] stands SFC bodies in by their interface; [`matiec_lib`] adds matiec's library blocks (typed counters, PID …) a project uses as ST POUs. What the reader did that changes meaning or skips vendor data is a [`Note`]
//! (a warning with its place). The mapping, the order rules and their sources:
//! docs/plcopen.md; the research behind them: docs/design/plcopen-semantics.md.
//!
//! Invariants: every error is one [`LoadError`] located at the XML node it is about (line and
//! column computed from its byte offset); a construct the reader does not handle is an error,
//! never dropped; a program loads whole or not at all.

mod black_box;
mod block_types;
mod data_types;
mod elementary;
mod expression;
mod fb_actions;
mod fbd;
mod fbd_loops;
mod il_body;
mod il_parse;
mod interface;
mod ld;
mod ld_block;
mod ld_flow;
mod ld_logic;
mod ld_power;
mod library;
mod matiec_lib;
mod pins;
mod project;
mod sfc;
mod sfc_lower;
mod st_body;
mod st_lower;
mod st_scope;
mod textual;
mod user_functions;
mod wiring;
mod write_places;
mod xml;

pub use xml::{ExecOrder, Note, Notes, MAX_XML_BYTES, NAMESPACES};

use plc_diag::LoadError;
use plc_syntax as syntax;

/// True when the text is XML rather than JSON: its first non-blank character is `<`.
pub fn looks_like_xml(text: &str) -> bool {
    text.trim_start_matches('\u{feff}')
        .trim_start()
        .starts_with('<')
}

/// Which part of a project to read: the program POU `pou` alone (`--pou`, any case), and the
/// configuration `configuration` (`--configuration`, any case) of a project with several
/// (IEC 61131-3 2.7: each configuration is its own controller); `None`: every program instance
/// of the configuration, and the first configuration in file order (a [`Notes::configurations`]
/// warning names the others).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct Pick<'a> {
    pub pou: Option<&'a str>,
    pub configuration: Option<&'a str>,
}

impl<'a> Pick<'a> {
    /// Only the program POU `pou`, when given.
    pub fn pou(pou: Option<&'a str>) -> Pick<'a> {
        Pick {
            pou,
            configuration: None,
        }
    }
}

/// Reads a PLCopen project into the surface syntax, with the reader's notes (errors carry line
/// and column).
pub fn parse(text: &str) -> Result<(syntax::Program<'static>, Notes), LoadError> {
    parse_selected(text, Pick::default())
}

/// [`parse`], keeping only the program POU named `pick.pou` (any case) when it is given: it is
/// then the main program, as if the project had no other (an error listing the programs when
/// there is none of that name); and reading the configuration `pick.configuration` (an error
/// listing the configurations when there is none of that name).
pub fn parse_selected(
    text: &str,
    pick: Pick,
) -> Result<(syntax::Program<'static>, Notes), LoadError> {
    parse_for(text, pick, false)
}

/// [`parse_selected`]; with `exec` (for `run` and `c`), each ST body that lowers to rungs is
/// read as those rungs ([`st_lower`]), not as a stand-in rung per statement.
pub fn parse_for(
    text: &str,
    pick: Pick,
    exec: bool,
) -> Result<(syntax::Program<'static>, Notes), LoadError> {
    parse_refusing(text, pick, exec, Vec::new())
}

/// [`parse_for`], the calls of the functions `refuse` names (lower-case name, why) read as
/// black boxes.
pub fn parse_refusing(
    text: &str,
    pick: Pick,
    exec: bool,
    refuse: Vec<(String, String)>,
) -> Result<(syntax::Program<'static>, Notes), LoadError> {
    let doc = xml::parse(text)?;
    let ns = xml::project_namespace(&doc).map_err(|e| e.locate(text))?;
    let mut notes = Notes {
        exec,
        refuse_functions: refuse,
        ..Notes::default()
    };
    let mut program =
        project::program(xml::Tc6 { ns }, &doc, pick, &mut notes).map_err(|e| e.locate(text))?;
    program.skipped = std::mem::take(&mut notes.skipped);
    Ok((program, notes))
}

/// The error `run` gives for what the reader noted it cannot execute (a string in an LD or FBD
/// body), located at that place.
pub fn run_refusal(note: Note, text: &str) -> LoadError {
    xml::error(note.origin, "run", note.message).locate(text)
}

/// A note as the command line prints it after `warning: ` (`FILE:LINE:COLUMN: message`).
pub fn note_text(file: &str, text: &str, n: &Note) -> String {
    match n.origin.line_column(text) {
        Some((l, c)) => format!("{file}:{l}:{c}: {}", n.message),
        None => format!("{file}: {}", n.message),
    }
}
