//! The tables of rows of one source file (`Tables`): the rows of its functions in the order
//! they run, the kernels they use, and the calls that run them.
//!
//! Consecutive rows of one kernel make one run, one call
//! `_pou__kK((uint8_t *)self, _pou__tF + first, count, ctx)`; the caller (`ladder`) ends the run
//! (`take_call`) before any other line of C, so rows run in the order they are pushed. Not here:
//! which rungs are rows (`rows`), the kernels' C (`kernel`).

use super::kernel;
use super::shape::Row;
use super::text::push;
use std::collections::BTreeSet;

/// The rows of the functions of one source file: one table (data file `plc_table{file}.c`)
/// that holds them in the order they run, whatever their kernels, so a scan reads it front to
/// back (with a table per kernel, every short run started on a cache line of its own); the
/// kernels used, and the run not yet called (its kernel, first entry, rows).
pub(crate) struct Tables {
    file: usize,
    /// The C type of the entries (`Kernels::entry_type`).
    ty: &'static str,
    text: String,
    entries: usize,
    used: BTreeSet<u32>,
    run: Option<(u32, usize, usize)>,
}

impl Tables {
    pub(super) fn new(file: usize, ty: &'static str) -> Tables {
        Tables {
            file,
            ty,
            text: String::new(),
            entries: 0,
            used: BTreeSet::new(),
            run: None,
        }
    }

    /// Adds `row` (rung `id`); the call of the run it ends, if it starts another.
    pub(super) fn push(&mut self, row: &Row, id: &str) -> Option<String> {
        let call = match self.run {
            Some((k, _, _)) if k != row.kernel => self.take_call(),
            _ => None,
        };
        match &mut self.run {
            Some((_, _, n)) => *n += 1,
            None => self.run = Some((row.kernel, self.entries, 1)),
        }
        self.used.insert(row.kernel);
        let nums: Vec<String> = row.slots.iter().map(u32::to_string).collect();
        push(
            &mut self.text,
            format_args!("    {}, /* {id} */\n", nums.join(", ")),
        );
        self.entries += row.slots.len();
        call
    }

    /// The call of the run of rows pushed since the last call, if any.
    pub(super) fn take_call(&mut self) -> Option<String> {
        let (k, first, n) = self.run.take()?;
        Some(format!(
            "_pou__k{k}((uint8_t *)self, _pou__t{} + {first}, {n}, ctx);",
            self.file
        ))
    }

    /// The declarations the functions' C needs (empty: no rows).
    pub(super) fn declarations(&self) -> String {
        if self.entries == 0 {
            return String::new();
        }
        let mut s = format!("extern const {} _pou__t{}[];\n", self.ty, self.file);
        for &k in &self.used {
            push(&mut s, format_args!("{};\n", kernel::decl(k, self.ty)));
        }
        s
    }

    /// The data file (name stem, text), if there are rows.
    pub(super) fn data_file(&self) -> Option<(String, String)> {
        if self.entries == 0 {
            return None;
        }
        Some((
            format!("plc_table{}", self.file),
            format!(
                "/* Rows of contacts and coils: byte offsets (docs/c.md). */\n#include <stdint.h>\n\n\
                 const {} _pou__t{}[{}] = {{\n{}}};\n",
                self.ty, self.file, self.entries, self.text
            ),
        ))
    }
}
