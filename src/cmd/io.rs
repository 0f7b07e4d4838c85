//! The commands' files: reading a program or an input file (standard input for `-`), checking
//! output paths before any work, and writing outputs atomically.
//!
//! Files are read by [`read_text`]: `-` is standard input, a folder, a file over
//! [`MAX_INPUT_BYTES`], binary data (a NUL byte) or text that is not UTF-8 is refused before
//! parsing (naming the byte offset), and a UTF-8 byte-order mark is dropped. Output paths can be
//! checked before any work with [`check_output_path`]. An output file is written under a
//! temporary name beside it and renamed into place only when the whole output is ready, so a
//! failure never leaves a half-written file; temporary files in the making are listed in a
//! registry that [`remove_temp_files`] empties (the binary calls it on SIGINT/SIGTERM), so a
//! stopped command leaves none behind. A program is recognised by its content ([`load_text`]:
//! S7-200 STL, PLCopen TC6 XML or JSON). Nothing here prints but the STL and PLCopen readers'
//! warnings (through [`super::errors`]).

use super::source::{SourceText, MAP_FROM};
use crate::diag::Shown;
use crate::fbd::Fbd;
use crate::model::Program;
use crate::read::LoadError;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

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

/// Largest file (or standard input) read whole: 2 GiB. Larger ones are refused before reading.
pub const MAX_INPUT_BYTES: u64 = 2 << 30;

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

/// Reads a whole text file (`-`: standard input) for `role`, refusing folders, files over
/// [`MAX_INPUT_BYTES`] (checked on the metadata, before reading), binary data and text that is
/// not UTF-8; a UTF-8 byte-order mark is dropped. A large regular file is mapped rather than
/// read ([`SourceText`]).
pub fn read_text(path: &Path, role: FileRole) -> Result<SourceText, CliError> {
    use std::io::ErrorKind;
    let err = |e| CliError::io(role, path, e);
    let too_large = |len: u64| {
        err(invalid(
            ErrorKind::FileTooLarge,
            format!(
                "the file is larger than the limit of {} GiB{}",
                MAX_INPUT_BYTES >> 30,
                if len > MAX_INPUT_BYTES {
                    format!(" ({len} bytes)")
                } else {
                    String::new()
                }
            ),
        ))
    };
    let bytes = if is_stdin(path) {
        let mut bytes = Vec::new();
        std::io::stdin()
            .lock()
            .take(MAX_INPUT_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(err)?;
        if bytes.len() as u64 > MAX_INPUT_BYTES {
            return Err(too_large(0));
        }
        bytes
    } else {
        let meta = std::fs::metadata(path).map_err(err)?;
        if meta.is_dir() {
            return Err(err(invalid(
                ErrorKind::IsADirectory,
                "it is a folder, not a file".into(),
            )));
        }
        if meta.len() > MAX_INPUT_BYTES {
            return Err(too_large(meta.len()));
        }
        if meta.is_file() && meta.len() >= MAP_FROM {
            let file = std::fs::File::open(path).map_err(err)?;
            if let Some(text) = SourceText::mapped(&file, check_text) {
                return text.map_err(|m| err(invalid(ErrorKind::InvalidData, m)));
            }
        }
        std::fs::read(path).map_err(err)?
    };
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
    load_program_for_run_selecting(path, None)
}

/// [`load_program_for_run`] keeping, with `select` (`--pou`), only that program of a PLCopen
/// project ([`crate::load::plcopen_selected`]); `select` on another kind of file is an error.
pub fn load_program_for_run_selecting(
    path: &Path,
    select: Option<&str>,
) -> Result<(Program, Fbd), CliError> {
    let (file, text) = read_program_text(path)?;
    load_text_for(file, &text, Purpose::Run, select)
}

/// [`load_text`] keeping, with `select` (`--pou`), only that program of a PLCopen project;
/// `select` on another kind of text is an error.
pub fn load_text_selecting(
    file: String,
    text: &str,
    select: Option<&str>,
) -> Result<(Program, Fbd), CliError> {
    load_text_for(file, text, Purpose::Analyse, select)
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
    load_text_for(file, text, Purpose::Analyse, None)
}

/// What a program is loaded for: `run` refuses what it cannot execute, the analyses do not.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Purpose {
    Analyse,
    Run,
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
    use crate::read::{plcopen, stl};
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
    select: Option<&str>,
) -> Result<(Program, Fbd), CliError> {
    let format = format_of(&file, text);
    if format == Format::Stl {
        if let Some(name) = select {
            return Err(CliError::Usage(format!(
                "{file}: --pou {name} selects a program of a PLCopen project or of a JSON program with a configuration, and this is an STL program (the DOT report's --pou draws one POU of any program: add --format dot)"
            )));
        }
        return crate::load::stl(text).map_err(|error| CliError::load(file, text, error));
    }
    if format == Format::PlcOpen {
        let load = match purpose {
            Purpose::Analyse => crate::load::plcopen_selected,
            Purpose::Run => crate::load::plcopen_for_run_selected,
        };
        let (p, f, notes) =
            load(text, select).map_err(|error| CliError::load(file.clone(), text, error))?;
        warn_notes(PLCOPEN_NOTE, &file, text, &notes);
        return Ok((p, f));
    }
    match select {
        Some(name) => crate::load::program_and_fbd_from_json_selected(text, name),
        None => crate::load::program_and_fbd_from_json(text),
    }
    .map_err(|error| CliError::load(file, text, error))
}

/// The code of a PLCopen reader's note (what it read only through an interface, ignored, or
/// ordered otherwise than the file).
pub const PLCOPEN_NOTE: &str = "W0501";
/// Prints a reader's notes as warnings with `code`.
fn warn_notes(code: &'static str, file: &str, text: &str, notes: &[crate::read::plcopen::Note]) {
    for n in notes {
        super::errors::warn(&Shown::warning(
            code,
            n.message.clone(),
            file,
            text,
            n.origin,
        ));
    }
}

/// Checks, before any work, that an output file can be written at `path`: not a folder, in a
/// folder that exists and lets us create a file (probed with the temporary name, then removed).
pub fn check_output_path(path: &Path, role: FileRole) -> Result<(), CliError> {
    if path.is_dir() {
        return Err(CliError::io(
            role,
            path,
            invalid(
                std::io::ErrorKind::IsADirectory,
                "it is a folder, not a file".into(),
            ),
        ));
    }
    let tmp = temp_name(path);
    let probe = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp);
    match probe {
        Ok(f) => {
            drop(f);
            let _ = std::fs::remove_file(&tmp);
            Ok(())
        }
        // Our own leftover (same process id) cannot be: create_new failed on someone else's.
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(output_error(path, role, e)),
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

/// The temporary name beside `path`: `.NAME.tmp-PID`.
fn temp_name(path: &Path) -> PathBuf {
    let mut tmp = path.to_path_buf();
    tmp.set_file_name(format!(
        ".{}.tmp-{}",
        path.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        std::process::id()
    ));
    tmp
}

/// Temporary files being written now (removed by [`remove_temp_files`] on a signal).
static TEMP_FILES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn temp_files() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    TEMP_FILES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary file in the making and keeps the registry locked, so that no new one
/// is started and none is renamed into place: call it only right before exiting (the binary
/// does on SIGINT/SIGTERM).
pub fn remove_temp_files() {
    let files = temp_files();
    for f in files.iter() {
        let _ = std::fs::remove_file(f);
    }
    std::mem::forget(files);
}

/// Writes `contents` to `out` (atomically) or to standard output.
pub fn write_output(out: Option<&Path>, contents: &str) -> Result<(), CliError> {
    write_output_with(out, |w| w.write_all(contents.as_bytes()))
}

/// Streams output produced by `write` to `out` or to standard output. A file is written under a
/// temporary name beside `out` and renamed into place only when `write` succeeded, so a failure
/// never leaves a partial file.
pub fn write_output_with(
    out: Option<&Path>,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    use std::io::Write;
    match out {
        None => {
            let mut stdout = std::io::BufWriter::new(std::io::stdout().lock());
            // A closed pipe (`| head`) is not an error worth reporting.
            let _ = write(&mut stdout).and_then(|_| stdout.flush());
            Ok(())
        }
        Some(path) => write_file_as(path, FileRole::Output, write),
    }
}

/// Writes the file `path` (for `role`, which errors name) from `write`: under a temporary name
/// beside it, registered for removal on a signal, then renamed into place; on any error the
/// temporary file is removed and nothing is left.
pub fn write_file_as(
    path: &Path,
    role: FileRole,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    let tmp = temp_name(path);
    temp_files().push(tmp.clone());
    let unregister = |tmp: &Path| temp_files().retain(|t| t != tmp);
    let file = match std::fs::File::create(&tmp) {
        Ok(f) => f,
        Err(e) => {
            unregister(&tmp);
            return Err(output_error(path, role, e));
        }
    };
    let mut file = file;
    let result = super::background::write_in_background(&mut file, write);
    drop(file);
    let mut files = temp_files();
    let result = result.and_then(|_| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    files.retain(|t| *t != tmp);
    drop(files);
    result.map_err(|e| CliError::io(role, path, e))
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
    fn temporary_names_sit_beside_the_file() {
        let t = temp_name(Path::new("out/r.json"));
        assert_eq!(
            t,
            PathBuf::from(format!("out/.r.json.tmp-{}", std::process::id()))
        );
        assert_eq!(folder_of(Path::new("r.json")), Path::new("."));
    }
}
