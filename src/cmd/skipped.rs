//! POUs whose bodies no command executes (a PLCopen ST, IL or SFC body, read only as stand-in
//! rungs that keep every value: [`plc_model::Pou::skipped`]): `run` and `c` refuse them
//! unless given `--allow-skipped`, and then list them in their output. The analyses (`report`)
//! keep them: the reader's warning W0501 says what each stand-in reads and writes.
//!
//! It does not decide what a stand-in is (the reader does) nor how an output shows the list.

use super::CliError;
use plc_model::{Pou, Program};
use std::path::Path;

/// One skipped POU as the outputs list it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SkippedPou {
    pub pou: String,
    /// `ST`, `IL`, `SFC`.
    pub language: String,
    /// 1-based line and column of the body in the program file.
    pub position: Option<(u32, u32)>,
    /// What in the body is not executed, and where (an ST construct the lowering refuses).
    pub why: Option<String>,
}

impl SkippedPou {
    /// `CounterST (ST body at 483:11)`.
    pub fn text(&self) -> String {
        match self.position {
            Some((l, c)) => format!("{} ({} body at {l}:{c})", self.pou, self.language),
            None => format!("{} ({} body)", self.pou, self.language),
        }
    }

    pub fn json(&self) -> serde_json::Value {
        let (line, column) = self.position.unzip();
        serde_json::json!({
            "pou": self.pou,
            "language": self.language,
            "line": line,
            "column": column,
        })
    }
}

/// The skipped POUs of `p`, in POU order.
pub fn skipped_pous(p: &Program) -> Vec<SkippedPou> {
    p.pous().iter().filter_map(skipped_pou).collect()
}

fn skipped_pou(pou: &Pou) -> Option<SkippedPou> {
    let s = pou.skipped.as_deref()?;
    Some(SkippedPou {
        pou: pou.name.clone(),
        language: s.language.clone(),
        position: s.position,
        why: s.why.clone(),
    })
}

/// Refuses `p`, read from `file`, when a POU's body is not executed and `allowed` is false:
/// one error naming the first such POU and where its body is. `what`: what the command does
/// with `--allow-skipped` ("run the rest of the project"), or `None` for a command without it.
pub fn refuse_skipped(
    p: &Program,
    file: &Path,
    allowed: bool,
    what: Option<&str>,
) -> Result<(), CliError> {
    let all = skipped_pous(p);
    let Some(first) = all.first().filter(|_| !allowed) else {
        return Ok(());
    };
    let file = if file == Path::new("-") {
        "<stdin>".to_string()
    } else {
        file.display().to_string()
    };
    let place = match first.position {
        Some((l, c)) => format!("{file}:{l}:{c}"),
        None => file,
    };
    let more = match all.len() - 1 {
        0 => String::new(),
        1 => " (and 1 more POU)".to_string(),
        n => format!(" (and {n} more POUs)"),
    };
    let help = match what {
        Some(what) => format!("give --allow-skipped to {what} without it"),
        None => "its STL cannot be written".to_string(),
    };
    let why = match &first.why {
        Some(w) => format!(": {w} is not executed yet"),
        None => String::new(),
    };
    Err(CliError::Usage(format!(
        "{place}: pou {}: its {} body is not executed{why} (it is read only as stand-in rungs that keep every value){more}; {help}",
        first.pou, first.language
    )))
}
