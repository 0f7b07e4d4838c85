//! The commands' files: reading a program or an input file (standard input for `-`), checking
//! output paths before any work, and writing outputs atomically.
//!
//! Files are read by [`read_text`]: `-` is standard input, a folder, anything over
//! [`MAX_INPUT_BYTES`] (every read is capped, a device or FIFO too), binary data (a NUL byte)
//! or text that is not UTF-8 is refused before parsing (naming the byte offset), and a UTF-8
//! byte-order mark is dropped. Output paths can be checked before any work with
//! [`check_output_path`]. An output file is written by what its path names
//! ([`write_file_as`]): a new or regular file under a fresh, unpredictable temporary name beside
//! it (created exclusively, never through a symbolic link) and renamed into place only when the
//! whole output is ready, so a failure never leaves a half-written file; a device or FIFO
//! directly; a symbolic link is refused. Temporary files and folders in the making are listed in
//! a registry that [`remove_temp_files`] empties (the binary calls it on SIGINT/SIGTERM), so a
//! stopped command leaves none behind. Standard output is written by [`write_stream`], the one
//! place that does: a write error is an error, a closed pipe is not. A program is recognised by
//! its content ([`load_text`]: S7-200 STL, PLCopen TC6 XML or JSON). Nothing here prints but the
//! STL and PLCopen readers' warnings (through `super::stderr`) and the output itself.
//!
//! Not here: an output that is atomic on a device or FIFO (it cannot be), or following a
//! symbolic link at `-o` (refused: replacing the link would not write its target, writing
//! through it could not be atomic).

use super::source::{SourceText, MAP_FROM};
pub use super::temp::remove_temp_files;
pub(crate) use super::temp::{
    create_in_temp_folder, create_temp_folder, discard_temp, put_folder_in_place,
};
use super::temp::{create_temp_file, put_file_in_place};
#[cfg(test)]
use super::temp::{random_suffix, temp_name};
use plc_diag::Shown;
use plc_fbd::Fbd;
pub use plc_load::Pick;
use plc_model::Program;
use plc_read::LoadError;
use std::io::Read;
use std::path::Path;
#[cfg(test)]
use std::path::PathBuf;

/// Which file of a command an I/O error is about (the name the user gave it).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FileRole {
    /// The program (`FILE` argument, `-` for standard input).
    Program,
    /// `--inputs` of `run`.
    Inputs,
    /// `-o`.
    Output,
    /// `--trace` of `run`.
    Trace,
}

impl FileRole {
    fn verb(self) -> &'static str {
        match self {
            FileRole::Program | FileRole::Inputs => "read",
            FileRole::Output | FileRole::Trace => "write",
        }
    }
    fn what(self) -> &'static str {
        match self {
            FileRole::Program => "the program",
            FileRole::Inputs => "--inputs",
            FileRole::Output => "-o",
            FileRole::Trace => "--trace",
        }
    }
}

/// An I/O error's text without the `(os error N)` suffix of the standard library.
fn io_reason(e: &std::io::Error) -> String {
    let s = e.to_string();
    match (s.rfind(" (os error "), s.ends_with(')')) {
        (Some(i), true) => s[..i].to_string(),
        _ => s,
    }
}

/// An error of a command, with what the user needs to find its cause.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The program file is not a valid program: `file:line:column: message` for syntax
    /// errors, `file: rung R at path: message` for the others (one line per error when there
    /// are several, each naming the file); `shown` is what the command line prints (see
    /// [`CliError::load`] and [`super::errors`]).
    #[error("{}", error.in_file(file))]
    Load {
        file: String,
        error: LoadError,
        shown: Vec<Shown>,
    },
    /// A file could not be read or written: `cannot read the program P: reason`,
    /// `cannot write -o P: reason` (see [`FileRole`]).
    #[error("cannot {} {} {path}: {}", role.verb(), role.what(), io_reason(source))]
    Io {
        role: FileRole,
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// A standard stream could not be written: `cannot write <stdout>: reason` (a closed pipe
    /// is not an error: see [`write_stream`]).
    #[error("cannot write {stream}: {}", io_reason(source))]
    Stream {
        stream: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// An argument is not valid.
    #[error("{0}")]
    Usage(String),
    /// The worker threads of the parallel executor could not be started.
    #[error("cannot start the worker threads: {0}")]
    Threads(String),
    /// A run ran, and its report was written, but it faulted (a division by zero, a loop past
    /// its cap) or its sequential and parallel runs differed.
    #[error("{0}")]
    Run(String),
}

impl CliError {
    /// Exit code: 1 for a run that faulted or whose modes differed ([`CliError::Run`]), 2 for
    /// every other error (bad program, arguments, files). README and docs/diagnostics.md list
    /// them.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Run(_) => 1,
            _ => 2,
        }
    }

    /// The error of loading `text`, the program file named `file`, with its diagnostics made
    /// ready to show (the text is not kept).
    pub fn load(file: String, text: &str, error: LoadError) -> CliError {
        CliError::Load {
            shown: Shown::load_error(&file, text, &error),
            file,
            error,
        }
    }

    /// An I/O error about `path` in `role`.
    pub fn io(role: FileRole, path: &Path, source: std::io::Error) -> CliError {
        CliError::Io {
            role,
            path: display_name(path),
            source,
        }
    }
}

/// Largest file (or standard input, device or FIFO) read whole: 2 GiB. A larger regular file is
/// refused on its size, before reading; anything else is refused once it has given one byte more.
pub const MAX_INPUT_BYTES: u64 = 2 << 30;

/// The environment variable that lowers [`MAX_INPUT_BYTES`] (to a number of bytes), so that
/// tests can reach the limit without reading 2 GiB. It cannot raise the limit; it is not a
/// user's option and the user documentation does not list it.
const MAX_INPUT_VAR: &str = "PLC_DEPS_MAX_INPUT_BYTES";

/// The limit on what is read whole: [`MAX_INPUT_BYTES`], or less with [`MAX_INPUT_VAR`].
fn max_input_bytes() -> u64 {
    std::env::var(MAX_INPUT_VAR)
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
        .map_or(MAX_INPUT_BYTES, |v| v.min(MAX_INPUT_BYTES))
}

/// How a path is named in messages: `<stdin>` for `-`.
pub(crate) fn display_name(path: &Path) -> String {
    if is_stdin(path) {
        "<stdin>".to_string()
    } else {
        path.display().to_string()
    }
}

pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

fn invalid(kind: std::io::ErrorKind, message: String) -> std::io::Error {
    std::io::Error::new(kind, message)
}

/// Where the UTF-8 text of `bytes` starts (after a leading byte-order mark), or why they are not
/// text: the byte offset of the first NUL byte (binary data) or of the first byte that is not
/// UTF-8, whichever is first.
fn check_text(bytes: &[u8]) -> Result<usize, String> {
    let nul = bytes.iter().position(|&b| b == 0);
    if let Err(e) = std::str::from_utf8(bytes) {
        let at = e.valid_up_to();
        if nul.is_none_or(|n| n > at) {
            let byte = bytes[at];
            return Err(format!(
                "not UTF-8 text (byte 0x{byte:02x} at offset {at} is not valid UTF-8)"
            ));
        }
    }
    if let Some(n) = nul {
        return Err(format!("binary data, not text (a NUL byte at offset {n})"));
    }
    Ok(if bytes.starts_with("\u{feff}".as_bytes()) {
        3
    } else {
        0
    })
}

/// The bytes as UTF-8 text without a leading byte-order mark, or why not ([`check_text`]).
fn utf8_text(bytes: Vec<u8>) -> Result<String, String> {
    let start = check_text(&bytes)?;
    let mut text = String::from_utf8(bytes).map_err(|e| e.to_string())?;
    text.drain(..start);
    Ok(text)
}

/// The message of a file over `cap` bytes (`len`, its size, when known).
fn too_large_text(cap: u64, len: Option<u64>) -> String {
    let limit = if cap.is_multiple_of(1 << 30) {
        format!("{} GiB", cap >> 30)
    } else {
        format!("{cap} bytes")
    };
    match len {
        Some(len) => format!("the file is larger than the limit of {limit} ({len} bytes)"),
        None => format!("the file is larger than the limit of {limit}"),
    }
}

/// What is read at a time by [`read_capped`] (and checked for a NUL byte).
const READ_CHUNK: u64 = 1 << 20;

/// Reads `from` to its end, but never more than `cap + 1` bytes (more than `cap` means too
/// large: an endless device or FIFO stops there), and stops after the first chunk that holds a
/// NUL byte: such bytes are binary data, and [`check_text`] names the same first bad byte in
/// them as in the whole. `expected` is the size to reserve (a regular file's length).
fn read_capped(from: &mut impl Read, cap: u64, expected: u64) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::with_capacity(expected.min(cap) as usize + 1);
    let mut from = from.take(cap + 1);
    loop {
        let before = bytes.len();
        let n = (&mut from).take(READ_CHUNK).read_to_end(&mut bytes)?;
        if n == 0 || bytes[before..].contains(&0) {
            return Ok(bytes);
        }
    }
}

/// Reads a whole text file (`-`: standard input) for `role`, refusing folders, anything over
/// [`MAX_INPUT_BYTES`] (a regular file on its size, before reading; a device, FIFO or standard
/// input once it gave more: every read is capped), binary data and text that is not UTF-8; a
/// UTF-8 byte-order mark is dropped. A large regular file is mapped rather than read
/// ([`SourceText`]).
pub fn read_text(path: &Path, role: FileRole) -> Result<SourceText, CliError> {
    use std::io::ErrorKind;
    let err = |e| CliError::io(role, path, e);
    let cap = max_input_bytes();
    let too_large = |len| err(invalid(ErrorKind::FileTooLarge, too_large_text(cap, len)));
    let bytes = if is_stdin(path) {
        read_capped(&mut std::io::stdin().lock(), cap, 0).map_err(err)?
    } else {
        // The checks are on the file opened (fstat), not on the path, which may change meanwhile.
        let mut file = std::fs::File::open(path).map_err(err)?;
        let meta = file.metadata().map_err(err)?;
        if meta.is_dir() {
            return Err(err(invalid(
                ErrorKind::IsADirectory,
                "it is a folder, not a file".into(),
            )));
        }
        let mut expected = 0;
        if meta.is_file() {
            if meta.len() > cap {
                return Err(too_large(Some(meta.len())));
            }
            if meta.len() >= MAP_FROM {
                // The mapping's length is the file's when it is made, which may have grown.
                let check = |bytes: &[u8]| match bytes.len() as u64 {
                    len if len > cap => Err(too_large_text(cap, Some(len))),
                    _ => check_text(bytes),
                };
                if let Some(text) = SourceText::mapped(&file, check) {
                    return text.map_err(|m| err(invalid(ErrorKind::InvalidData, m)));
                }
            }
            expected = meta.len();
        }
        read_capped(&mut file, cap, expected).map_err(err)?
    };
    if bytes.len() as u64 > cap {
        return Err(too_large(None));
    }
    utf8_text(bytes)
        .map(SourceText::owned)
        .map_err(|m| err(invalid(ErrorKind::InvalidData, m)))
}

/// Reads a program's text (`-`: standard input; see [`read_text`]) and the name that errors
/// about it use (`<stdin>` for `-`).
pub fn read_program_text(path: &Path) -> Result<(String, SourceText), CliError> {
    Ok((display_name(path), read_text(path, FileRole::Program)?))
}

/// Reads and checks a program file (`-`: standard input).
pub fn load_program(path: &Path) -> Result<Program, CliError> {
    load_program_and_fbd(path).map(|(p, _)| p)
}

/// Reads and checks a program file (`-`: standard input) for `run`, with its FBD bodies: a
/// PLCopen project with something `run` cannot execute (a string in an LD or FBD body) is an
/// error.
pub fn load_program_for_run(path: &Path) -> Result<(Program, Fbd), CliError> {
    load_program_for_run_selecting(path, Pick::default())
}

/// [`load_program_for_run`] keeping, with `pick.pou` (`--pou`), only that program of a PLCopen
/// project ([`plc_load::plcopen_selected`]), and reading the configuration `pick.configuration`
/// (`--configuration`) of a project with several; `--configuration` on another kind of file
/// is an error.
pub fn load_program_for_run_selecting(path: &Path, pick: Pick) -> Result<(Program, Fbd), CliError> {
    let (file, text) = read_program_text(path)?;
    load_text_for(file, &text, Purpose::Run, pick)
}

/// [`load_text`] keeping, with `pick` (`--pou`, `--configuration`), only that program and
/// configuration of a PLCopen project, as [`load_program_for_run_selecting`].
pub fn load_text_selecting(
    file: String,
    text: &str,
    pick: Pick,
) -> Result<(Program, Fbd), CliError> {
    load_text_for(file, text, Purpose::Analyse, pick)
}

/// [`load_program_and_fbd`] for code generation: a PLCopen ST body that lowers to rungs is
/// those rungs, as `run` executes them; `configuration` as [`load_text_selecting`].
pub fn load_program_for_c(
    path: &Path,
    configuration: Option<&str>,
) -> Result<(Program, Fbd), CliError> {
    let (file, text) = read_program_text(path)?;
    load_text_lowered(file, &text, configuration)
}

/// [`load_text`] for what writes a program out (`c`, `il`, `convert`): a PLCopen ST body that
/// lowers to rungs is those rungs, as `run` executes them, not the analysis's stand-ins;
/// `configuration` as [`load_text_selecting`].
pub fn load_text_lowered(
    file: String,
    text: &str,
    configuration: Option<&str>,
) -> Result<(Program, Fbd), CliError> {
    let pick = Pick {
        pou: None,
        configuration,
    };
    load_text_for(file, text, Purpose::Generate, pick)
}

/// Reads and checks a program file (`-`: standard input), with its FBD bodies as written.
pub fn load_program_and_fbd(path: &Path) -> Result<(Program, Fbd), CliError> {
    let (file, text) = read_program_text(path)?;
    load_text(file, &text)
}

/// Checks a program's text, recognised by its content: S7-200 STL when its first line opens a
/// block or a declaration section (or the file is named `.stl`/`.awl`), PLCopen TC6 XML when it
/// starts with `<` (the PLCopen reader's notes go to standard error as warnings W0501), else the JSON format.
pub fn load_text(file: String, text: &str) -> Result<(Program, Fbd), CliError> {
    load_text_for(file, text, Purpose::Analyse, Pick::default())
}

/// What a program is loaded for: `run` refuses what it cannot execute, the analyses do not.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Purpose {
    Analyse,
    Run,
    /// `c`: ST bodies lowered as for `run`, nothing refused here (`c` refuses skipped bodies).
    Generate,
}

/// The formats a program file is read in.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Format {
    Stl,
    PlcOpen,
    Json,
}

/// The format of program text `text` of file `file`, recognised as [`load_text`] says.
pub fn format_of(file: &str, text: &str) -> Format {
    use plc_read::{plcopen, stl};
    let lower = file.to_ascii_lowercase();
    if stl::looks_like_stl(text) || lower.ends_with(".stl") || lower.ends_with(".awl") {
        Format::Stl
    } else if plcopen::looks_like_xml(text) {
        Format::PlcOpen
    } else {
        Format::Json
    }
}

fn load_text_for(
    file: String,
    text: &str,
    purpose: Purpose,
    pick: Pick,
) -> Result<(Program, Fbd), CliError> {
    let format = format_of(&file, text);
    let select = pick.pou;
    if let (Some(c), Format::Stl | Format::Json) = (pick.configuration, format) {
        return Err(CliError::Usage(format!(
            "--configuration {c}: {file} is not a PLCopen project; --configuration chooses one of a PLCopen project's configurations"
        )));
    }
    if format == Format::Stl {
        return match select {
            Some(name) => plc_load::stl_selected(text, name),
            None => plc_load::stl(text),
        }
        .map_err(|error| CliError::load(file, text, error));
    }
    if format == Format::PlcOpen {
        let load = match purpose {
            Purpose::Analyse => plc_load::plcopen_selected,
            Purpose::Run => plc_load::plcopen_for_run_selected,
            Purpose::Generate => plc_load::plcopen_lowered_selected,
        };
        let read = load(text, pick).map_err(|error| CliError::load(file.clone(), text, error))?;
        warn_notes(
            CONFIGURATIONS_NOTE,
            &file,
            text,
            read.configurations.as_slice(),
        );
        warn_notes(PLCOPEN_NOTE, &file, text, &read.notes);
        return Ok((read.program, read.fbd));
    }
    match select {
        Some(name) => plc_load::program_and_fbd_from_json_selected(text, name),
        None => plc_load::program_and_fbd_from_json(text),
    }
    .map_err(|error| CliError::load(file, text, error))
}

/// The code of a PLCopen reader's note (what it read only through an interface, ignored, or
/// ordered otherwise than the file).
pub const PLCOPEN_NOTE: &str = "W0501";
/// The code of the note that a PLCopen project has several configurations and the first is
/// read (`--configuration` chooses another).
pub const CONFIGURATIONS_NOTE: &str = "W0502";
/// Prints a reader's notes as warnings with `code`.
fn warn_notes(code: &'static str, file: &str, text: &str, notes: &[plc_read::plcopen::Note]) {
    for n in notes {
        super::stderr::warn(&Shown::warning(
            code,
            n.message.clone(),
            file,
            text,
            n.origin,
        ));
    }
}

/// What an output path names now, which decides how it is written (see [`output_target`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Target {
    /// Nothing yet, or a regular file: written under a temporary name, renamed over it.
    Replace,
    /// A character or block device or a FIFO (`/dev/null`, a named pipe): written directly, as
    /// replacing it would put a regular file in its place.
    Special,
    /// The process's own standard output or error, named `/dev/stdout`, `/dev/fd/1`,
    /// `/dev/stderr` or `/dev/fd/2` (symbolic links into `/proc`): written to the stream.
    Stream(Stream),
}

/// A standard stream that output can go to.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Stream {
    Stdout,
    Stderr,
}

impl Stream {
    /// How the stream is named in messages.
    fn name(self) -> &'static str {
        match self {
            Stream::Stdout => "<stdout>",
            Stream::Stderr => "<stderr>",
        }
    }
}

/// How output to `path` is written, or why it cannot be: a folder, a socket, or a symbolic link
/// (never followed: a link cannot be replaced atomically, and writing through it would write
/// wherever it points) other than the standard streams' names.
fn output_target(path: &Path) -> std::io::Result<Target> {
    use std::io::ErrorKind;
    match path.to_str() {
        Some("/dev/stdout" | "/dev/fd/1") => return Ok(Target::Stream(Stream::Stdout)),
        Some("/dev/stderr" | "/dev/fd/2") => return Ok(Target::Stream(Stream::Stderr)),
        _ => {}
    }
    let meta = match std::fs::symlink_metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(Target::Replace),
        Err(e) => return Err(e),
    };
    let kind = meta.file_type();
    if kind.is_file() {
        Ok(Target::Replace)
    } else if kind.is_dir() {
        Err(invalid(
            ErrorKind::IsADirectory,
            "it is a folder, not a file".into(),
        ))
    } else if kind.is_symlink() {
        Err(invalid(ErrorKind::InvalidInput, SYMLINK_REFUSED.into()))
    } else if is_special(&kind) {
        Ok(Target::Special)
    } else {
        Err(invalid(
            ErrorKind::InvalidInput,
            "it is neither a file nor a device nor a FIFO".into(),
        ))
    }
}

/// Why a symbolic link is not written through (docs/scan.md, "Files").
pub(crate) const SYMLINK_REFUSED: &str =
    "it is a symbolic link, which is not followed (name the file it points to)";

/// A character or block device or a FIFO.
#[cfg(unix)]
fn is_special(kind: &std::fs::FileType) -> bool {
    use std::os::unix::fs::FileTypeExt;
    kind.is_char_device() || kind.is_block_device() || kind.is_fifo()
}

#[cfg(not(unix))]
fn is_special(_: &std::fs::FileType) -> bool {
    false
}

/// Checks, before any work, that an output file can be written at `path`: not a folder, a
/// symbolic link or a socket ([`output_target`]); a file to replace must be in a folder that
/// exists and lets us create a file (probed with a temporary file, then removed). A device or
/// FIFO is not opened here (opening a FIFO waits for its reader).
pub fn check_output_path(path: &Path, role: FileRole) -> Result<(), CliError> {
    match output_target(path).map_err(|e| CliError::io(role, path, e))? {
        Target::Replace => {
            let (probe, tmp) = create_temp_file(path).map_err(|e| output_error(path, role, e))?;
            drop(probe);
            discard_temp(&tmp);
            Ok(())
        }
        Target::Special | Target::Stream(_) => Ok(()),
    }
}

/// The error of creating a file at `path`: a missing folder is named as such.
fn output_error(path: &Path, role: FileRole, e: std::io::Error) -> CliError {
    let folder = folder_of(path);
    let e = if !folder.is_dir() {
        let what = if folder.exists() {
            format!("{} is not a folder", folder.display())
        } else {
            format!("the folder {} does not exist", folder.display())
        };
        invalid(e.kind(), what)
    } else {
        e
    };
    CliError::io(role, path, e)
}

/// The folder a file at `path` goes in (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Writes `contents` to `out` (atomically) or to standard output.
pub fn write_output(out: Option<&Path>, contents: &str) -> Result<(), CliError> {
    write_output_with(out, |w| w.write_all(contents.as_bytes()))
}

/// Streams output produced by `write` to `out` ([`write_file_as`]) or to standard output
/// ([`write_stream`]).
pub fn write_output_with(
    out: Option<&Path>,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    match out {
        None => write_stream(Stream::Stdout, write),
        Some(path) => write_file_as(path, FileRole::Output, write),
    }
}

/// Writes output produced by `write` to a standard stream, buffered. Every write of the crate to
/// standard output goes through here. A closed pipe (`| head`: `BrokenPipe`) ends the output
/// quietly; any other error (a full disk) is `cannot write <stdout>: reason`.
pub fn write_stream(
    stream: Stream,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    use std::io::Write;
    fn to(
        mut w: std::io::BufWriter<impl Write>,
        write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
    ) -> std::io::Result<()> {
        write(&mut w)?;
        w.flush()
    }
    let result = match stream {
        Stream::Stdout => to(std::io::BufWriter::new(std::io::stdout().lock()), write),
        Stream::Stderr => to(std::io::BufWriter::new(std::io::stderr().lock()), write),
    };
    match result {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(CliError::Stream {
            stream: stream.name(),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// Writes the file `path` (for `role`, which errors name) from `write`, by what `path` names
/// ([`output_target`]): a new or regular file under a fresh temporary name beside it
/// (registered for removal on a signal), renamed into place once complete, so that on any error
/// nothing is left and an existing file is unchanged; a device or FIFO directly; a standard
/// stream's name as [`write_stream`]. A folder, symbolic link or socket is refused.
pub fn write_file_as(
    path: &Path,
    role: FileRole,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    let err = |e| CliError::io(role, path, e);
    match output_target(path).map_err(err)? {
        Target::Stream(stream) => write_stream(stream, write),
        Target::Special => {
            let mut file = open_special(path).map_err(err)?;
            super::background::write_in_background(&mut file, write).map_err(err)
        }
        Target::Replace => {
            let (mut file, tmp) =
                create_temp_file(path).map_err(|e| output_error(path, role, e))?;
            let result = super::background::write_in_background(&mut file, write);
            drop(file);
            put_file_in_place(&tmp, path, result).map_err(err)
        }
    }
}

/// Opens the device or FIFO `path` for writing, without following a symbolic link, and checks
/// that it still is one (not a regular file put there since it was looked at, which would be
/// written in place).
fn open_special(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW);
    }
    let file = options.open(path)?;
    if is_special(&file.metadata()?.file_type()) {
        Ok(file)
    } else {
        Err(invalid(
            std::io::ErrorKind::InvalidInput,
            "it was replaced by a file while it was opened".into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn io_errors_name_the_file_keep_their_source_and_exit_with_2() {
        use std::error::Error;
        let e = CliError::io(
            FileRole::Trace,
            Path::new("t.csv"),
            std::io::Error::from_raw_os_error(2),
        );
        assert_eq!(
            e.to_string(),
            "cannot write --trace t.csv: No such file or directory"
        );
        let source = e.source().expect("the io::Error is the source");
        assert!(source.downcast_ref::<std::io::Error>().is_some());
        assert_eq!(e.exit_code(), 2);
        assert_eq!(CliError::Usage("x".into()).exit_code(), 2);
    }

    #[test]
    fn text_is_utf8_without_nul_and_loses_its_byte_order_mark() {
        assert_eq!(utf8_text(b"\xef\xbb\xbf{}".to_vec()).unwrap(), "{}");
        assert_eq!(utf8_text("é".as_bytes().to_vec()).unwrap(), "é");
        assert_eq!(
            utf8_text(b"ab\xc3".to_vec()).unwrap_err(),
            "not UTF-8 text (byte 0xc3 at offset 2 is not valid UTF-8)"
        );
        assert_eq!(
            utf8_text(b"a\0\xff".to_vec()).unwrap_err(),
            "binary data, not text (a NUL byte at offset 1)"
        );
        assert_eq!(
            utf8_text(b"\xff\0".to_vec()).unwrap_err(),
            "not UTF-8 text (byte 0xff at offset 0 is not valid UTF-8)"
        );
    }

    #[test]
    fn temporary_names_sit_beside_the_file_and_fit_in_255_bytes() {
        let t = temp_name(Path::new("out/r.json"), "tmp", 0xab);
        assert_eq!(t, PathBuf::from("out/.r.json.tmp-00000000000000ab"));
        assert_eq!(folder_of(Path::new("r.json")), Path::new("."));
        assert_eq!(
            temp_name(Path::new("r.json"), "old", 1),
            PathBuf::from(".r.json.old-0000000000000001")
        );
        // A 255-byte name is cut, at a character boundary (é is two bytes).
        let long = format!("{}a", "é".repeat(127));
        assert_eq!(long.len(), 255);
        let t = temp_name(Path::new(&long), "tmp", u64::MAX);
        let name = t.file_name().unwrap().to_str().unwrap();
        assert_eq!(name, format!(".{}.tmp-ffffffffffffffff", "é".repeat(116)));
        assert_eq!(name.len(), 254);
    }

    #[test]
    fn temporary_names_are_not_predictable() {
        let a = random_suffix();
        let b = random_suffix();
        assert_ne!(a, b);
    }

    #[test]
    fn reads_stop_at_the_cap_and_after_the_first_nul() {
        let endless = std::io::repeat(b'a');
        let bytes = read_capped(&mut { endless }, 10, 0).unwrap();
        assert_eq!(
            bytes.len(),
            11,
            "one byte over the cap tells it is too large"
        );
        // /dev/zero: stops after the first chunk, long before the cap.
        let bytes = read_capped(&mut std::io::repeat(0), MAX_INPUT_BYTES, 0).unwrap();
        assert_eq!(bytes.len() as u64, READ_CHUNK);
        assert_eq!(
            check_text(&bytes).unwrap_err(),
            "binary data, not text (a NUL byte at offset 0)"
        );
        let bytes = read_capped(&mut &b"{}"[..], 10, 2).unwrap();
        assert_eq!(bytes, b"{}");
        assert_eq!(
            too_large_text(1 << 20, None),
            "the file is larger than the limit of 1048576 bytes"
        );
        assert_eq!(
            too_large_text(MAX_INPUT_BYTES, Some(3 << 30)),
            "the file is larger than the limit of 2 GiB (3221225472 bytes)"
        );
    }
}
