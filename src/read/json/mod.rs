//! The JSON program format (docs/format.md, docs/fbd.md) → [`syntax::Program`], streamed.
//!
//! Two passes over the text, neither of which builds a `serde_json::Value` tree of the document:
//! the first reads the program object with serde, keeping each part it will look at later as a
//! `&RawValue` (a slice of the text: syntax is fully checked here, so a syntax error is always
//! reported first, with line and column); the second reads each part — variables, each rung, each
//! element — with streaming visitors into the syntax types. The byte offset of a raw part in the
//! text is its [`Origin`]. Every visitor accepts any JSON value: a value of the wrong shape or an
//! unknown field becomes a [`Problem`] at the node (a path suffix relative to it), so reading
//! never stops at the first one. A UTF-8 byte-order mark at the start of the text is skipped.
//!
//! Deliberately not here: names, types, ids, labels and every other rule that needs more than
//! one node (`crate::resolve`).

mod element;
mod fbd;
mod ladder;
mod scalar;

use crate::diag::{Invalid, LoadError};
use crate::syntax::{self, Body, Origin, Problem, Scalar, Text, Var, VarClass};
use ladder::RungDe;
use scalar::{parse_raw, AnyScalar, Container};
use serde::de::{IgnoredAny, MapAccess, SeqAccess};
use serde_json::value::RawValue;

/// Reads a program file's text into the surface syntax. Only syntax errors fail here.
pub fn parse(text: &str) -> Result<syntax::Program<'_>, LoadError> {
    let body = text.strip_prefix('\u{feff}').unwrap_or(text);
    let top: Container = serde_json::from_str(body).map_err(|e| syntax_error(body, &e))?;
    let mut r = Reader {
        base: text.as_ptr() as usize,
        program: syntax::Program::default(),
    };
    match top {
        Container::Object(entries) => r.program_object(entries)?,
        Container::Array(_) => r.problem("", shape("a JSON object (the program)", &Scalar::Array)),
        Container::Other(s) => r.problem("", shape("a JSON object (the program)", &s)),
    }
    Ok(r.program)
}

fn syntax_error(text: &str, e: &serde_json::Error) -> LoadError {
    let message = e.to_string();
    let message = match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message,
    };
    if text.trim().is_empty() {
        return LoadError::Syntax {
            line: e.line().max(1),
            column: 1,
            message: "the file is empty (expected a JSON object, the program)".into(),
        };
    }
    LoadError::Syntax {
        line: e.line(),
        // serde_json counts the column of an error at the start of a line as 0.
        column: e.column().max(1),
        message,
    }
}

fn shape(expected: &'static str, found: &Scalar) -> Invalid {
    Invalid::Shape {
        expected,
        found: found.kind(),
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_owned()
    } else {
        format!("{path}.{key}")
    }
}

/// A raw part, parsed. The first pass checked its syntax, so an error is a visitor's bug: it is
/// still reported as located data, never a panic.
fn raw<'de, T: serde::Deserialize<'de>>(v: &'de RawValue, path: &str) -> Result<T, LoadError> {
    parse_raw(v).map_err(|e| {
        LoadError::invalid(
            None,
            path,
            Invalid::Shape {
                expected: "a value the reader can read",
                found: e.to_string(),
            },
        )
    })
}

/// Drains an array, for "found an array" messages.
pub(super) fn scalar_of_seq<'de, A: SeqAccess<'de>>(mut seq: A) -> Result<Scalar<'de>, A::Error> {
    while seq.next_element::<IgnoredAny>()?.is_some() {}
    Ok(Scalar::Array)
}

/// Drains an object, for "found an object" messages.
pub(super) fn scalar_of_map<'de, A: MapAccess<'de>>(mut map: A) -> Result<Scalar<'de>, A::Error> {
    while map.next_entry::<IgnoredAny, IgnoredAny>()?.is_some() {}
    Ok(Scalar::Object)
}

type Entries<'de> = Vec<(Text<'de>, &'de RawValue)>;

struct Reader<'de> {
    /// Address of the start of the whole text (offsets are relative to it).
    base: usize,
    program: syntax::Program<'de>,
}

fn get<'e, 'de>(entries: &'e Entries<'de>, key: &str) -> Option<&'de RawValue> {
    entries.iter().find(|(k, _)| k == key).map(|(_, v)| *v)
}

impl<'de> Reader<'de> {
    fn origin(&self, v: &RawValue) -> Origin {
        Origin::at(v.get().as_ptr() as usize - self.base)
    }

    fn problem(&mut self, path: &str, kind: Invalid) {
        self.program.problems.push(Problem {
            at: path.to_owned(),
            kind,
        });
    }

    fn unknown_keys(&mut self, e: &Entries, allowed: &[&str], what: &'static str, path: &str) {
        if let Some((k, _)) = e.iter().find(|(k, _)| !allowed.contains(&k.as_ref())) {
            let kind = Invalid::UnknownField {
                field: k.to_string(),
                what,
                allowed: allowed.join(", "),
            };
            self.problem(&join(path, k), kind);
        }
    }

    /// A string field; `None` (with a problem) when it is not a string.
    fn string(&mut self, v: &'de RawValue, path: &str) -> Result<Option<Text<'de>>, LoadError> {
        match raw::<AnyScalar>(v, path)?.0 {
            Scalar::Str(s) => Ok(Some(s)),
            other => {
                self.problem(path, shape("a string", &other));
                Ok(None)
            }
        }
    }

    /// An object of raw parts; `None` (with a problem) when it is not an object.
    fn object(
        &mut self,
        v: &'de RawValue,
        path: &str,
        expected: &'static str,
    ) -> Result<Option<Entries<'de>>, LoadError> {
        match raw::<Container>(v, path)? {
            Container::Object(e) => Ok(Some(e)),
            Container::Array(_) => {
                self.problem(path, shape(expected, &Scalar::Array));
                Ok(None)
            }
            Container::Other(s) => {
                self.problem(path, shape(expected, &s));
                Ok(None)
            }
        }
    }

    /// An array of raw parts; `None` (with a problem) when it is not an array.
    fn array(
        &mut self,
        v: &'de RawValue,
        path: &str,
    ) -> Result<Option<Vec<&'de RawValue>>, LoadError> {
        match raw::<Container>(v, path)? {
            Container::Array(a) => Ok(Some(a)),
            Container::Object(_) => {
                self.problem(path, shape("an array", &Scalar::Object));
                Ok(None)
            }
            Container::Other(s) => {
                self.problem(path, shape("an array", &s));
                Ok(None)
            }
        }
    }

    fn program_object(&mut self, top: Entries<'de>) -> Result<(), LoadError> {
        const KEYS: &[&str] = &[
            "program",
            "vars",
            "rungs",
            "fbd",
            "subroutines",
            "function_blocks",
            "comment",
        ];
        self.unknown_keys(&top, KEYS, "the program", "");
        match get(&top, "program") {
            None => self.problem(
                "",
                Invalid::MissingField {
                    field: "program",
                    what: "the program",
                },
            ),
            Some(v) => {
                if let Some(s) = self.string(v, "program")? {
                    self.program.name = s;
                }
            }
        }
        if let Some(c) = get(&top, "comment") {
            self.program.comment = match raw::<AnyScalar>(c, "comment")?.0 {
                Scalar::Str(s) => Some(s),
                _ => None,
            };
        }
        if let Some(fbs) = get(&top, "function_blocks") {
            self.function_blocks(fbs)?;
        }
        if let Some(vars) = get(&top, "vars") {
            self.program.vars = self.vars(vars, "vars")?;
        }
        self.program.body = self.body(&top, "", "the program")?;
        if let Some(subs) = get(&top, "subroutines") {
            self.subroutines(subs)?;
        }
        Ok(())
    }

    fn subroutines(&mut self, subs: &'de RawValue) -> Result<(), LoadError> {
        let Some(entries) = self.object(subs, "subroutines", "an object of subroutines")? else {
            return Ok(());
        };
        for (name, v) in entries {
            let path = format!("subroutines.{name}");
            let origin = self.origin(v);
            let Some(o) = self.object(v, &path, "an object (a subroutine)")? else {
                continue;
            };
            self.unknown_keys(
                &o,
                &["vars", "rungs", "fbd", "comment"],
                "a subroutine",
                &path,
            );
            let vars = match get(&o, "vars") {
                Some(vs) => self.vars(vs, &format!("{path}.vars"))?,
                None => Vec::new(),
            };
            let body = self.body(&o, &path, "a subroutine")?;
            self.program.subroutines.push(syntax::Subroutine {
                origin,
                name,
                vars,
                body,
            });
        }
        Ok(())
    }

    fn function_blocks(&mut self, fbs: &'de RawValue) -> Result<(), LoadError> {
        let Some(entries) = self.object(fbs, "function_blocks", "an object")? else {
            return Ok(());
        };
        for (name, v) in entries {
            let path = format!("function_blocks.{name}");
            let origin = self.origin(v);
            let Some(o) = self.object(v, &path, "an object")? else {
                continue;
            };
            self.unknown_keys(
                &o,
                &["vars", "inputs", "outputs", "fbd", "rungs", "comment"],
                "a function block",
                &path,
            );
            let decl = |r: &mut Self, key: &str| match get(&o, key) {
                Some(vs) => r.vars(vs, &format!("{path}.{key}")),
                None => Ok(Vec::new()),
            };
            let inputs = decl(self, "inputs")?;
            let outputs = decl(self, "outputs")?;
            let vars = decl(self, "vars")?;
            let body = if get(&o, "rungs").is_none() && get(&o, "fbd").is_none() {
                self.problem(
                    &path,
                    Invalid::MissingField {
                        field: "fbd` or `rungs",
                        what: "a function block",
                    },
                );
                None
            } else {
                self.body(&o, &path, "a function block")?
            };
            self.program.function_blocks.push(syntax::FunctionBlock {
                origin,
                name,
                inputs,
                outputs,
                vars,
                body,
            });
        }
        Ok(())
    }

    /// The body of a POU: `rungs` or `fbd`, not both.
    fn body(
        &mut self,
        o: &Entries<'de>,
        path: &str,
        what: &'static str,
    ) -> Result<Option<Body<'de>>, LoadError> {
        match (get(o, "rungs"), get(o, "fbd")) {
            (Some(_), Some(_)) => {
                self.problem(
                    &join(path, "fbd"),
                    Invalid::Misplaced {
                        what: "`fbd`",
                        place: "together with `rungs` (a body is one of them)",
                    },
                );
                Ok(None)
            }
            (None, Some(f)) => Ok(Some(Body::Fbd(fbd::body(self.base, f)?))),
            (Some(r), None) => {
                let rp = join(path, "rungs");
                let Some(items) = self.array(r, &rp)? else {
                    return Ok(None);
                };
                let mut rungs = Vec::with_capacity(items.len());
                for item in items {
                    let RungDe(mut rung) = raw(item, &rp)?;
                    rung.origin = self.origin(item);
                    rungs.push(rung);
                }
                Ok(Some(Body::Rungs(rungs)))
            }
            (None, None) => {
                self.problem(
                    path,
                    Invalid::MissingField {
                        field: "rungs",
                        what,
                    },
                );
                Ok(None)
            }
        }
    }

    fn vars(&mut self, v: &'de RawValue, path: &str) -> Result<Vec<Var<'de>>, LoadError> {
        let Some(items) = self.array(v, path)? else {
            return Ok(Vec::new());
        };
        let mut out = Vec::with_capacity(items.len());
        for item in items {
            out.push(self.var(item, path)?);
        }
        Ok(out)
    }

    fn var(&mut self, v: &'de RawValue, path: &str) -> Result<Var<'de>, LoadError> {
        let mut var = Var {
            origin: self.origin(v),
            name: Text::Borrowed(""),
            ty: Text::Borrowed(""),
            class: VarClass::Default,
            init: None,
            problem: None,
        };
        let entries = match raw::<Container>(v, path)? {
            Container::Object(e) => e,
            Container::Array(_) => {
                var.problem = Some(Problem::new(
                    "",
                    shape("an object (a variable)", &Scalar::Array),
                ));
                return Ok(var);
            }
            Container::Other(s) => {
                var.problem = Some(Problem::new("", shape("an object (a variable)", &s)));
                return Ok(var);
            }
        };
        let allowed = ["name", "type", "class", "init", "comment"];
        let mut problem = entries
            .iter()
            .find(|(k, _)| !allowed.contains(&k.as_ref()))
            .map(|(k, _)| {
                Problem::new(
                    format!(".{k}"),
                    Invalid::UnknownField {
                        field: k.to_string(),
                        what: "a variable",
                        allowed: allowed.join(", "),
                    },
                )
            });
        let text = |key: &'static str, problem: &mut Option<Box<Problem>>| {
            let found = match get(&entries, key) {
                None => {
                    let kind = Invalid::MissingField {
                        field: key,
                        what: "a variable",
                    };
                    problem.get_or_insert_with(|| Problem::new("", kind));
                    return Ok(Text::Borrowed(""));
                }
                Some(j) => raw::<AnyScalar>(j, path)?.0,
            };
            match found {
                Scalar::Str(s) => Ok(s),
                other => {
                    problem.get_or_insert_with(|| {
                        Problem::new(format!(".{key}"), shape("a string", &other))
                    });
                    Ok(Text::Borrowed(""))
                }
            }
        };
        var.name = text("name", &mut problem)?;
        var.ty = text("type", &mut problem)?;
        if let Some(c) = get(&entries, "class") {
            var.class = match raw::<AnyScalar>(c, path)?.0 {
                Scalar::Str(s) if s == "input" => VarClass::Input,
                Scalar::Str(s) if s == "output" => VarClass::Output,
                Scalar::Str(s) if s == "memory" => VarClass::Memory,
                Scalar::Str(s) => {
                    let kind = Invalid::Shape {
                        expected: "\"input\", \"output\" or \"memory\"",
                        found: format!("\"{s}\""),
                    };
                    problem.get_or_insert_with(|| Problem::new(".class", kind));
                    VarClass::Default
                }
                other => {
                    problem
                        .get_or_insert_with(|| Problem::new(".class", shape("a string", &other)));
                    VarClass::Default
                }
            };
        }
        if let Some(i) = get(&entries, "init") {
            var.init = Some(raw::<AnyScalar>(i, path)?.0);
        }
        var.problem = problem;
        Ok(var)
    }
}
