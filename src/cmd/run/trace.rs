//! The `--trace` CSV: the traced columns (`--trace-vars`), the header and one line per scan.

use crate::cmd::io::CliError;
use plc_exec::{Addr, Machine};
use plc_model::{Field, Program, Type, Value, VarId, VarRef};
use std::io::Write;

/// The CSV cell of one traced value: BOOL 1/0, integers, bit strings and TIME (ms) as exact
/// decimal numbers, REAL and LREAL shortest.
pub(super) fn cell(v: Value) -> String {
    match v {
        Value::Bool(b) => (if b { "1" } else { "0" }).to_string(),
        Value::Real(f) => format!("{f}"),
        v => match v.as_f64() {
            Some(f) => format!("{f}"),
            None => v.as_i128().unwrap_or(0).to_string(),
        },
    }
}

/// A STRING's trace cell: its text quoted as CSV quotes a field (RFC 4180: `"` doubled).
pub(super) fn text_cell(text: &str) -> String {
    format!("\"{}\"", text.replace('"', "\"\""))
}

pub(super) struct Trace<'a> {
    pub(super) out: &'a mut dyn Write,
    pub(super) cols: Vec<(Addr, Type)>,
    pub(super) line: String,
    pub(super) error: Option<std::io::Error>,
}

/// Resolves `--trace-vars` (names, or instance fields `T1.Q`) to (header, variable, type)
/// columns, each once (in the order first asked for); `None`: every variable but the hidden edge memories, instances as their Q/ET/PT or
/// Q/CV/PV fields.
pub(super) fn trace_columns(
    p: &Program,
    vars: Option<&[String]>,
) -> Result<Vec<(String, VarRef, Type)>, CliError> {
    let fields_of = |v: VarId| -> Vec<(Field, Type)> {
        match p.var(v).ty {
            Type::Fb(fb) => Field::all(fb)
                .iter()
                .filter_map(|f| Field::lookup(fb, f.name()))
                .collect(),
            _ => vec![],
        }
    };
    let mut cols = Vec::new();
    let mut add = |v: VarId, field: Option<(Field, Type)>| {
        let name = &p.var(v).name;
        match field {
            Some((f, ty)) => cols.push((
                format!("{name}.{}", f.name()),
                VarRef {
                    var: v,
                    field: Some(f),
                },
                ty,
            )),
            None => cols.push((
                name.clone(),
                VarRef {
                    var: v,
                    field: None,
                },
                p.var(v).ty,
            )),
        }
    };
    match vars {
        None => {
            for v in p.vars().ids().filter(|&v| !p.var(v).hidden) {
                let fields = fields_of(v);
                if fields.is_empty() {
                    add(v, None);
                } else {
                    for f in fields {
                        add(v, Some(f));
                    }
                }
            }
        }
        Some(names) => {
            for raw in names {
                let name = raw.trim();
                let (base, field) = match name.split_once('.') {
                    Some((b, f)) => (b, Some(f)),
                    None => (name, None),
                };
                let Some(v) = p
                    .vars()
                    .iter()
                    .position(|x| x.name == base)
                    .map(|i| p.vars().id(i))
                else {
                    return Err(CliError::Usage(format!(
                        "--trace-vars: unknown variable `{name}`"
                    )));
                };
                let fields = fields_of(v);
                match field {
                    None if fields.is_empty() => add(v, None),
                    None => {
                        for f in fields {
                            add(v, Some(f));
                        }
                    }
                    Some(f) => match fields
                        .iter()
                        .find(|(x, _)| x.name().eq_ignore_ascii_case(f))
                    {
                        Some(&ft) => add(v, Some(ft)),
                        None => {
                            return Err(CliError::Usage(format!(
                                "--trace-vars: `{name}`: {base} has no field {f}"
                            )))
                        }
                    },
                }
            }
        }
    }
    // A column asked for twice (`T1.Q,T1`) is written once, where it was first asked for.
    let mut seen = std::collections::HashSet::new();
    cols.retain(|(_, r, _)| seen.insert(*r));
    Ok(cols)
}

impl<'a> Trace<'a> {
    pub(super) fn new(
        m: &Machine,
        cols: &[(String, VarRef, Type)],
        out: &'a mut dyn Write,
    ) -> Trace<'a> {
        let mut line = String::from("scan,time_ms");
        for (name, _, _) in cols {
            line.push(',');
            line.push_str(name);
        }
        line.push('\n');
        let error = out.write_all(line.as_bytes()).err();
        Trace {
            out,
            cols: cols.iter().map(|&(_, r, t)| (m.addr_of(r), t)).collect(),
            line,
            error,
        }
    }
}
