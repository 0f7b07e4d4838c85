//! `plc-deps c FILE -o DIR`: writes the C of a program (`plc_codegen::c`) into a folder,
//! all files or none.
//!
//! Atomicity: the files are written into a fresh temporary folder `.DIR.tmp-` + 16 random hex
//! digits beside DIR (made by `mkdir`, which never reuses an existing name or follows a symbolic
//! link; its files are created exclusively too) and renamed to DIR only when every file is
//! written. An existing DIR is refused unless it is empty or `--force` is given; with `--force`
//! the old DIR is first renamed aside (`.DIR.old-` + random digits), the new one renamed in,
//! then the old one removed — so DIR is always either the old folder, absent for the instant
//! between the two renames, or the complete new one. The temporary folders are in the registry
//! of `super::io`: a command stopped by SIGINT or SIGTERM removes them with all they hold. A
//! DIR that is a symbolic link is refused, as for every `-o`.

use super::io::{
    create_in_temp_folder, create_temp_folder, discard_temp, load_program_for_c,
    put_folder_in_place, CliError, FileRole, SYMLINK_REFUSED,
};
use plc_codegen::c::{generate, CConfig};
use std::fs;
use std::io::Write;
use std::path::PathBuf;

/// A validated `plc-deps c` invocation.
#[derive(Clone, Debug)]
pub struct CCommand {
    pub input: PathBuf,
    pub output: PathBuf,
    pub force: bool,
    /// `--allow-skipped`: write C for a program some of whose POU bodies are not executed
    /// (each such function says so in a comment); false: such a program is refused.
    pub allow_skipped: bool,
    /// `--dialect` (docs/dialects.md); `None`: the file's.
    pub dialect: Option<plc_model::Dialect>,
    /// The configuration of a PLCopen project with several (`--configuration`); `None`: the
    /// first in file order.
    pub configuration: Option<String>,
    pub config: CConfig,
}

/// `plc-deps c`: generates and writes the files.
pub fn c(cmd: &CCommand) -> Result<(), CliError> {
    let (mut p, fbd) = load_program_for_c(&cmd.input, cmd.configuration.as_deref())?;
    if let Some(d) = cmd.dialect {
        p.set_dialect(d);
    }
    super::skipped::refuse_skipped(&p, &cmd.input, cmd.allow_skipped, Some("write the C"))?;
    let dir = &cmd.output;
    let io = |e| CliError::io(FileRole::Output, dir, e);
    let exists = match fs::symlink_metadata(dir) {
        Ok(meta) if meta.file_type().is_symlink() => {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                SYMLINK_REFUSED,
            )))
        }
        Ok(meta) if !meta.is_dir() => {
            return Err(CliError::Usage(format!(
                "-o {}: exists and is not a folder",
                dir.display()
            )))
        }
        Ok(_) => true,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
        Err(e) => return Err(io(e)),
    };
    if exists {
        let nonempty = fs::read_dir(dir).map_err(io)?.next().is_some();
        if nonempty && !cmd.force {
            return Err(CliError::Usage(format!(
                "-o {}: the folder exists and is not empty (give --force to replace it)",
                dir.display()
            )));
        }
    }
    if let Some(parent) = dir.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(CliError::Usage(format!(
                "-o {}: the folder {} does not exist",
                dir.display(),
                parent.display()
            )));
        }
    }
    let files = generate(&p, &fbd, &cmd.config);
    let tmp = create_temp_folder(dir).map_err(io)?;
    let write_all = || -> std::io::Result<()> {
        for f in &files {
            create_in_temp_folder(&tmp, &f.name)?.write_all(f.text.as_bytes())?;
        }
        Ok(())
    };
    let old = write_all().and_then(|()| put_folder_in_place(&tmp, dir, exists));
    match old {
        Ok(old) => {
            if let Some(old) = old {
                discard_temp(&old);
            }
            Ok(())
        }
        Err(e) => {
            discard_temp(&tmp);
            Err(io(e))
        }
    }
}
