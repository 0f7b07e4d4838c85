//! `plc-deps c FILE -o DIR`: writes the C of a program (`crate::codegen::c`) into a folder,
//! all files or none.
//!
//! Atomicity: the files are written into a fresh temporary folder `.DIR.tmp-PID` beside DIR and
//! renamed to DIR only when every file is written. An existing DIR is refused unless it is
//! empty or `--force` is given; with `--force` the old DIR is first renamed aside
//! (`.DIR.old-PID`), the new one renamed in, then the old one removed — so DIR is always either
//! the old folder, absent for the instant between the two renames, or the complete new one.

use super::io::{load_program_and_fbd, CliError, FileRole};
use crate::codegen::c::{generate, CConfig};
use std::fs;
use std::path::{Path, PathBuf};

/// A validated `plc-deps c` invocation.
#[derive(Clone, Debug)]
pub struct CCommand {
    pub input: PathBuf,
    pub output: PathBuf,
    pub force: bool,
    /// `--allow-skipped`: write C for a program some of whose POU bodies are not executed
    /// (each such function says so in a comment); false: such a program is refused.
    pub allow_skipped: bool,
    pub config: CConfig,
}

fn sibling(dir: &Path, what: &str) -> PathBuf {
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty());
    let file = format!(".{name}.{what}-{}", std::process::id());
    match parent {
        Some(p) => p.join(file),
        None => PathBuf::from(file),
    }
}

/// `plc-deps c`: generates and writes the files.
pub fn c(cmd: &CCommand) -> Result<(), CliError> {
    let (p, fbd) = load_program_and_fbd(&cmd.input)?;
    super::skipped::refuse_skipped(&p, &cmd.input, cmd.allow_skipped, Some("write the C"))?;
    let dir = &cmd.output;
    let io = |e| CliError::io(FileRole::Output, dir, e);
    let exists = dir.exists();
    if exists {
        if !dir.is_dir() {
            return Err(CliError::Usage(format!(
                "-o {}: exists and is not a folder",
                dir.display()
            )));
        }
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
    let tmp = sibling(dir, "tmp");
    let write_all = || -> std::io::Result<()> {
        fs::create_dir(&tmp)?;
        for f in &files {
            fs::write(tmp.join(&f.name), &f.text)?;
        }
        Ok(())
    };
    if let Err(e) = write_all() {
        let _ = fs::remove_dir_all(&tmp);
        return Err(io(e));
    }
    let result = if exists {
        let old = sibling(dir, "old");
        fs::rename(dir, &old)
            .and_then(|()| fs::rename(&tmp, dir))
            .and_then(|()| fs::remove_dir_all(&old))
    } else {
        fs::rename(&tmp, dir)
    };
    result.map_err(|e| {
        let _ = fs::remove_dir_all(&tmp);
        io(e)
    })
}
