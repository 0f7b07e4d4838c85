//! The JSON program format (docs/format.md, docs/fbd.md) → [`syntax::Program`], in one pass.
//!
//! A hand-written [`cursor::Cursor`] walks the text once, and the readers here and in [`ladder`]
//! and [`element`] fill the syntax types as they go — no `serde_json::Value` tree, no second look
//! at any part, strings borrowed from the text, each series collected on a scratch stack and
//! stored in a `Vec` of its exact size. Every node gets the byte offset of its value (its
//! [`Origin`]); the key of an unknown field gets its own. Every reader accepts any JSON value: a
//! value of the wrong shape or an unknown field becomes a [`Problem`] at the node (a path suffix
//! relative to it, and the origin of the most precise node), so reading never stops at the first
//! one. The parts of an object are read in file order, each with its own problems, and put
//! together in the order the format lists them (a repeated key keeps its first place and its
//! last value). A syntax error stops the reading; its message and place are `serde_json`'s, asked
//! only then, so they read the same as they always have. A UTF-8 byte-order mark at the start of
//! the text is skipped (offsets still count it: they are offsets into the text as given).
//! Given a [`syntax::RungSink`] ([`parse_with`]), the reader offers it the program's variables
//! and main rungs at the start of the rung array, and hands over each rung as it is read
//! instead of keeping it.
//!
//! Deliberately not here: names, types, ids, labels and every other rule that needs more than
//! one node (`plc_resolve`). FBD bodies are read by [`fbd`].

mod configuration;
mod cursor;
mod element;
mod fbd;
mod ladder;
mod locate;

pub use locate::path_offset;

use cursor::{Cursor, Fail, P};
use plc_diag::{Invalid, LoadError};
use plc_syntax::{
    self as syntax, Body, Located, Name, Origin, Problem, RoutineKind, Scalar, Text, Var, VarClass,
};
use serde::de::IgnoredAny;

/// Reads a program file's text into the surface syntax. Only syntax errors fail here.
pub fn parse(text: &str) -> Result<syntax::Program<'_>, LoadError> {
    parse_with(text, None)
}

/// [`parse`], offering the main program's rungs to `sink` (see [`syntax::RungSink`]): when it
/// takes them, the tree's main body has none.
pub fn parse_with<'a>(
    text: &'a str,
    sink: Option<&mut dyn syntax::RungSink<'a>>,
) -> Result<syntax::Program<'a>, LoadError> {
    let start = if text.starts_with('\u{feff}') { 3 } else { 0 };
    let mut r = Reader::new(text, start, sink);
    match r.document() {
        Ok(program) => Ok(program),
        Err(Fail) => Err(syntax_error(text, start, r.c.offset())),
    }
}

/// The syntax error of a text the cursor refused at byte `at`, as `serde_json` words it.
#[cold]
fn syntax_error(text: &str, start: usize, at: usize) -> LoadError {
    let body = &text[start..];
    // Checked without building values first (a syntax error late in a big file); only what that
    // accepts (a string that does not decode, say) is read into values to find the error.
    let checked = serde_json::from_str::<IgnoredAny>(body)
        .and_then(|_| serde_json::from_str::<serde_json::Value>(body).map(drop));
    match checked {
        Err(e) if body.trim().is_empty() => LoadError::Syntax {
            line: e.line().max(1),
            column: 1,
            message: "the file is empty (expected a JSON object, the program)".into(),
        },
        Err(e) => {
            if let Some(error) = trailing_comma(text, start, e.line(), e.column()) {
                return error;
            }
            let message = e.to_string();
            let message = match message.rfind(" at line ") {
                Some(i) => message[..i].to_owned(),
                None => message,
            };
            LoadError::Syntax {
                line: e.line(),
                // serde_json counts the column of an error at the start of a line as 0.
                column: e.column().max(1),
                message,
            }
        }
        // The cursor refused what serde_json reads: a bug of the cursor, still located.
        Ok(_) => {
            let (line, column) = Origin::at(at).line_column(text).unwrap_or((1, 1));
            LoadError::Syntax {
                line: line as usize,
                column: column as usize,
                message: "the reader cannot read this value (a bug of plc-deps: please report it)"
                    .into(),
            }
        }
    }
}

/// A comma right before the `]` or `}` where serde_json stopped (at 1-based `line`, `column`
/// of the text after the byte-order mark): JSON allows none there (RFC 8259 §4, §5), and the
/// place to show is the comma, which may be lines before the bracket.
fn trailing_comma(text: &str, start: usize, line: usize, column: usize) -> Option<LoadError> {
    let body = &text[start..];
    let line_start = if line <= 1 {
        0
    } else {
        body.match_indices('\n').nth(line - 2)?.0 + 1
    };
    let at = line_start + column.max(1) - 1;
    let close = *body.as_bytes().get(at)?;
    if close != b']' && close != b'}' {
        return None;
    }
    let before = body[..at].trim_end_matches([' ', '\t', '\n', '\r']);
    if !before.ends_with(',') {
        return None;
    }
    let comma = start + before.len() - 1;
    let (line, column) = Origin::at(comma).line_column(text)?;
    let what = if close == b']' { "array" } else { "object" };
    Some(LoadError::Syntax {
        line: line as usize,
        column: column as usize,
        message: format!(
            "trailing comma: a value must follow `,` (JSON allows no comma before the `{}` that ends the {what})",
            close as char
        ),
    })
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

fn unknown_field(
    at: String,
    origin: Origin,
    field: &str,
    what: &'static str,
    allowed: &[&str],
) -> Problem {
    Problem {
        at,
        origin,
        kind: Invalid::UnknownField {
            field: field.to_owned(),
            what,
            allowed: allowed.join(", "),
        },
    }
}

/// A part of an object, with the problems found in it (kept apart until the parts are put
/// together in the format's order).
struct Part<T> {
    value: T,
    problems: Vec<Problem>,
}

/// The parts of a POU object (the program, a subroutine, a function block), as read.
#[derive(Default)]
struct Parts<'a> {
    /// The first key that is not allowed (in file order), with its origin.
    unknown: Option<(Text<'a>, Origin)>,
    name: Option<(Scalar<'a>, Origin)>,
    comment: Option<Scalar<'a>>,
    vars: Option<Part<Vec<Var<'a>>>>,
    inputs: Option<Part<Vec<Var<'a>>>>,
    outputs: Option<Part<Vec<Var<'a>>>>,
    rungs: Option<Part<Option<Vec<syntax::Rung<'a>>>>>,
    fbd: Option<syntax::FbdBody<'a>>,
    subroutines: Option<Part<Vec<syntax::Subroutine<'a>>>>,
    interrupts: Option<Part<Vec<syntax::Subroutine<'a>>>>,
    function_blocks: Option<Part<Vec<syntax::FunctionBlock<'a>>>>,
    configuration: Option<Result<plc_model::Configuration, Problem>>,
    dialect: Option<(Scalar<'a>, Origin)>,
}

const PROGRAM_KEYS: &[&str] = &[
    "program",
    "vars",
    "rungs",
    "fbd",
    "subroutines",
    "interrupts",
    "function_blocks",
    "configuration",
    "dialect",
    "comment",
];
const SUBROUTINE_KEYS: &[&str] = &["vars", "rungs", "fbd", "comment"];
const FB_KEYS: &[&str] = &["vars", "inputs", "outputs", "fbd", "rungs", "comment"];
const VAR_KEYS: &[&str] = &["name", "type", "class", "init", "comment"];

/// The reader: the cursor, the problems of the part being read, the scratch stacks of
/// elements and element keys (nested series and elements sit above their parents' entries), and
/// what the main program's rungs may be handed to.
pub(super) struct Reader<'a, 'r> {
    c: Cursor<'a>,
    problems: Vec<Problem>,
    elements: Vec<syntax::Element<'a>>,
    slots: Vec<element::SlotEntry<'a>>,
    sink: Option<&'r mut dyn syntax::RungSink<'a>>,
    /// The sink took the program's variables and rungs.
    streamed: bool,
}

impl<'a, 'r> Reader<'a, 'r> {
    fn new(
        text: &'a str,
        start: usize,
        sink: Option<&'r mut dyn syntax::RungSink<'a>>,
    ) -> Reader<'a, 'r> {
        Reader {
            c: Cursor::new(text, start),
            problems: Vec::new(),
            elements: Vec::with_capacity(64),
            slots: Vec::with_capacity(16),
            sink,
            streamed: false,
        }
    }

    /// At the main program's rung array: whether its variables and rungs go to the sink (they
    /// do when nothing read so far is malformed or needs more than the variables to resolve);
    /// they then leave the tree.
    fn offer(&mut self, parts: &mut Parts<'a>) -> bool {
        if std::mem::take(&mut self.streamed) {
            self.retract();
            return false;
        }
        let clean = self.problems.is_empty()
            && parts.unknown.is_none()
            && parts.fbd.is_none()
            && parts.function_blocks.is_none()
            && parts.vars.as_ref().is_none_or(|v| v.problems.is_empty());
        let rungs = self.c.remaining() / 128;
        match self.sink.as_deref_mut() {
            Some(sink) if clean => {
                let vars = parts.vars.take().map_or_else(Vec::new, |v| v.value);
                sink.start(vars, rungs);
                self.streamed = true;
            }
            _ => self.streamed = false,
        }
        self.streamed
    }

    /// A part the sink took is read again: it must not be used.
    fn retract(&mut self) {
        if let Some(sink) = self.sink.as_deref_mut() {
            sink.retract();
        }
    }

    fn problem(&mut self, at: impl Into<String>, origin: Origin, kind: Invalid) {
        self.problems.push(Problem {
            at: at.into(),
            origin,
            kind,
        });
    }

    /// Reads a part with problems of its own.
    fn part<T>(&mut self, read: impl FnOnce(&mut Self) -> P<T>) -> P<Part<T>> {
        let outer = std::mem::take(&mut self.problems);
        let value = read(self);
        let problems = std::mem::replace(&mut self.problems, outer);
        Ok(Part {
            value: value?,
            problems,
        })
    }

    fn document(&mut self) -> P<syntax::Program<'a>> {
        let origin = self.c.origin();
        let program = if self.c.peek() == Some(b'{') {
            self.program_object(origin)?
        } else {
            let found = self.c.scalar()?;
            let mut p = syntax::Program::default();
            p.problems.push(Problem {
                at: String::new(),
                origin,
                kind: shape("a JSON object (the program)", &found),
            });
            p
        };
        self.c.end()?;
        Ok(program)
    }

    /// At `{`: the parts of a POU object whose keys may be `allowed`.
    fn parts(&mut self, path: &str, allowed: &[&str]) -> P<Parts<'a>> {
        let mut parts = Parts::default();
        self.c.begin_object()?;
        let mut first = true;
        while let Some((key, key_origin)) = self.c.key(&mut first)? {
            if !allowed.contains(&key.as_ref()) {
                parts.unknown.get_or_insert((key, key_origin));
                self.c.skip()?;
                continue;
            }
            let origin = self.c.origin();
            let at = || join(path, &key);
            match key.as_ref() {
                "program" => parts.name = Some((self.c.scalar()?, origin)),
                "comment" => parts.comment = Some(self.c.scalar()?),
                "dialect" => parts.dialect = Some((self.c.scalar()?, origin)),
                "vars" if path.is_empty() && self.streamed => {
                    self.retract();
                    parts.vars = Some(self.part(|r| r.vars(&at()))?)
                }
                "vars" => parts.vars = Some(self.part(|r| r.vars(&at()))?),
                "inputs" => parts.inputs = Some(self.part(|r| r.vars(&at()))?),
                "outputs" => parts.outputs = Some(self.part(|r| r.vars(&at()))?),
                "rungs" => {
                    let streamed = path.is_empty() && self.offer(&mut parts);
                    parts.rungs = Some(self.part(|r| r.rungs(&at(), streamed))?)
                }
                "subroutines" => parts.subroutines = Some(self.part(|r| r.subroutines())?),
                "interrupts" => parts.interrupts = Some(self.part(|r| r.interrupts())?),
                "function_blocks" => {
                    parts.function_blocks = Some(self.part(|r| r.function_blocks())?)
                }
                "fbd" => parts.fbd = Some(fbd::body(&mut self.c)?),
                "configuration" => {
                    parts.configuration = Some(configuration::configuration(&mut self.c)?)
                }
                _ => self.c.skip()?,
            }
        }
        Ok(parts)
    }

    fn program_object(&mut self, origin: Origin) -> P<syntax::Program<'a>> {
        let parts = self.parts("", PROGRAM_KEYS)?;
        let mut p = syntax::Program {
            origin,
            ..syntax::Program::default()
        };
        let mut problems = Vec::new();
        if let Some((k, o)) = &parts.unknown {
            problems.push(unknown_field(
                k.to_string(),
                *o,
                k,
                "the program",
                PROGRAM_KEYS,
            ));
        }
        match parts.name {
            None => problems.push(Problem {
                at: String::new(),
                origin,
                kind: Invalid::MissingField {
                    field: "program",
                    what: "the program",
                },
            }),
            Some((Scalar::Str(s), o)) => {
                p.name = s;
                p.name_origin = o;
            }
            Some((other, o)) => problems.push(Problem {
                at: "program".into(),
                origin: o,
                kind: shape("a string", &other),
            }),
        }
        if let Some(Scalar::Str(s)) = parts.comment {
            p.comment = Some(s);
        }
        if let Some(fbs) = parts.function_blocks {
            problems.extend(fbs.problems);
            p.function_blocks = fbs.value;
        }
        if let Some(vars) = parts.vars {
            problems.extend(vars.problems);
            p.vars = vars.value;
        }
        p.body = body(
            parts.rungs,
            parts.fbd,
            "",
            "the program",
            origin,
            &mut problems,
        );
        // Subroutines first, then interrupt routines, each in file order.
        for routines in [parts.subroutines, parts.interrupts].into_iter().flatten() {
            problems.extend(routines.problems);
            p.subroutines.extend(routines.value);
        }
        match parts.configuration {
            Some(Ok(c)) => p.configuration = Some(c),
            Some(Err(problem)) => problems.push(problem),
            None => {}
        }
        // Whose rules `run` and `c` follow (docs/dialects.md); IEC when absent.
        match parts.dialect {
            None => {}
            Some((Scalar::Str(s), o)) => match plc_model::Dialect::from_name(&s) {
                Some(d) => p.dialect = d,
                None => problems.push(Problem {
                    at: "dialect".into(),
                    origin: o,
                    kind: Invalid::Shape {
                        expected: "a dialect (\"iec\", \"matiec\" or \"codesys\")",
                        found: format!("\"{s}\""),
                    },
                }),
            },
            Some((other, o)) => problems.push(Problem {
                at: "dialect".into(),
                origin: o,
                kind: shape("a dialect (\"iec\", \"matiec\" or \"codesys\")", &other),
            }),
        }
        p.problems = problems;
        Ok(p)
    }

    /// An object of named POU objects (`subroutines`, `function_blocks`); `None` for a value
    /// that is not an object (the problem recorded). Each entry is read by `read` (at its `{`)
    /// with its own problems, so that a repeated name keeps its first place and its last value.
    #[allow(clippy::type_complexity)]
    fn named<T>(
        &mut self,
        container: &'static str,
        expected: &'static str,
        entry: &'static str,
        read: fn(&mut Self, Text<'a>, Origin, &str) -> P<T>,
    ) -> P<Vec<T>> {
        let origin = self.c.origin();
        if self.c.peek() != Some(b'{') {
            let found = self.c.scalar()?;
            self.problem(container, origin, shape(expected, &found));
            return Ok(Vec::new());
        }
        let mut entries: Vec<(Text<'a>, Part<Option<T>>)> = Vec::new();
        self.c.begin_object()?;
        let mut first = true;
        while let Some((name, _)) = self.c.key(&mut first)? {
            let path = format!("{container}.{name}");
            let origin = self.c.origin();
            let part = self.part(|r| {
                if r.c.peek() == Some(b'{') {
                    read(r, name.clone(), origin, &path).map(Some)
                } else {
                    let found = r.c.scalar()?;
                    r.problem(path.as_str(), origin, shape(entry, &found));
                    Ok(None)
                }
            })?;
            match entries.iter_mut().find(|(q, _)| *q == name) {
                Some(e) => e.1 = part,
                None => entries.push((name, part)),
            }
        }
        let mut out = Vec::with_capacity(entries.len());
        for (_, part) in entries {
            self.problems.extend(part.problems);
            out.extend(part.value);
        }
        Ok(out)
    }

    fn subroutines(&mut self) -> P<Vec<syntax::Subroutine<'a>>> {
        self.named(
            "subroutines",
            "an object of subroutines",
            "an object (a subroutine)",
            |r, name, origin, path| r.routine(RoutineKind::Subroutine, name, origin, path),
        )
    }

    fn interrupts(&mut self) -> P<Vec<syntax::Subroutine<'a>>> {
        self.named(
            "interrupts",
            "an object of interrupt routines",
            "an object (an interrupt routine)",
            |r, name, origin, path| r.routine(RoutineKind::Interrupt, name, origin, path),
        )
    }

    /// One subroutine or interrupt routine, at its `{`.
    fn routine(
        &mut self,
        kind: RoutineKind,
        name: Text<'a>,
        origin: Origin,
        path: &str,
    ) -> P<syntax::Subroutine<'a>> {
        let what = match kind {
            RoutineKind::Subroutine => "a subroutine",
            RoutineKind::Interrupt => "an interrupt routine",
        };
        let parts = self.parts(path, SUBROUTINE_KEYS)?;
        if let Some((k, o)) = &parts.unknown {
            let p = unknown_field(join(path, k), *o, k, what, SUBROUTINE_KEYS);
            self.problems.push(p);
        }
        let vars = self.take(parts.vars);
        let body = body(
            parts.rungs,
            parts.fbd,
            path,
            what,
            origin,
            &mut self.problems,
        );
        Ok(syntax::Subroutine {
            origin,
            kind,
            name,
            vars,
            body,
        })
    }

    fn function_blocks(&mut self) -> P<Vec<syntax::FunctionBlock<'a>>> {
        self.named(
            "function_blocks",
            "an object",
            "an object",
            |r, name, origin, path| {
                let parts = r.parts(path, FB_KEYS)?;
                if let Some((k, o)) = &parts.unknown {
                    let p = unknown_field(join(path, k), *o, k, "a function block", FB_KEYS);
                    r.problems.push(p);
                }
                let inputs = r.take(parts.inputs);
                let outputs = r.take(parts.outputs);
                let vars = r.take(parts.vars);
                let body = if parts.rungs.is_none() && parts.fbd.is_none() {
                    r.problem(
                        path,
                        origin,
                        Invalid::MissingField {
                            field: "fbd` or `rungs",
                            what: "a function block",
                        },
                    );
                    None
                } else {
                    let what = "a function block";
                    body(parts.rungs, parts.fbd, path, what, origin, &mut r.problems)
                };
                Ok(syntax::FunctionBlock {
                    origin,
                    name,
                    inputs,
                    outputs,
                    vars,
                    body,
                })
            },
        )
    }

    /// The variables of a part, its problems now recorded.
    fn take(&mut self, part: Option<Part<Vec<Var<'a>>>>) -> Vec<Var<'a>> {
        match part {
            None => Vec::new(),
            Some(p) => {
                self.problems.extend(p.problems);
                p.value
            }
        }
    }

    /// An array of variable declarations at `path`.
    fn vars(&mut self, path: &str) -> P<Vec<Var<'a>>> {
        let origin = self.c.origin();
        if self.c.peek() != Some(b'[') {
            let found = self.c.scalar()?;
            self.problem(path, origin, shape("an array", &found));
            return Ok(Vec::new());
        }
        // The program's variables are sized for the rest of the text at a short declaration
        // each: a million of them would otherwise be moved twenty times, and what is reserved
        // and never touched costs no memory. (Once: not for every function block's inputs.)
        let mut out = match path {
            "vars" => Vec::with_capacity(self.c.remaining() / 32),
            _ => Vec::new(),
        };
        self.c.begin_array()?;
        let mut first = true;
        while self.c.item(&mut first)? {
            out.push(self.var()?);
        }
        Ok(out)
    }

    fn var(&mut self) -> P<Var<'a>> {
        let origin = self.c.origin();
        let mut var = Var {
            origin,
            name: Name::empty(),
            ty: Name::empty(),
            class: Located {
                value: VarClass::Default,
                origin: Origin::NONE,
            },
            init: None,
            problem: None,
        };
        if self.c.peek() != Some(b'{') {
            let found = self.c.scalar()?;
            let kind = shape("an object (a variable)", &found);
            var.problem = Some(Problem::new("", origin, kind));
            return Ok(var);
        }
        let (mut name, mut ty, mut class, mut unknown) = (None, None, None, None);
        self.c.begin_object()?;
        let mut first = true;
        while let Some((key, key_origin)) = self.c.key(&mut first)? {
            let at = self.c.origin();
            match key.as_ref() {
                "name" => name = Some((self.c.scalar()?, at)),
                "type" => ty = Some((self.c.scalar()?, at)),
                "class" => class = Some((self.c.scalar()?, at)),
                "init" => {
                    var.init = Some(Box::new(Located {
                        value: self.c.scalar()?,
                        origin: at,
                    }))
                }
                "comment" => self.c.skip()?,
                _ => {
                    self.c.skip()?;
                    unknown.get_or_insert((key, key_origin));
                }
            }
        }
        let mut problem = unknown.map(|(k, o)| {
            Box::new(unknown_field(
                format!(".{k}"),
                o,
                &k,
                "a variable",
                VAR_KEYS,
            ))
        });
        let mut text = |found: Option<(Scalar<'a>, Origin)>, key: &'static str| match found {
            None => {
                let kind = Invalid::MissingField {
                    field: key,
                    what: "a variable",
                };
                problem.get_or_insert_with(|| Problem::new("", origin, kind));
                Name::empty()
            }
            Some((Scalar::Str(s), o)) => Located {
                value: s,
                origin: o,
            },
            Some((other, o)) => {
                let kind = shape("a string", &other);
                problem.get_or_insert_with(|| Problem::new(format!(".{key}"), o, kind));
                Name::empty()
            }
        };
        var.name = text(name, "name");
        var.ty = text(ty, "type");
        if let Some((found, o)) = class {
            let value = match found {
                Scalar::Str(s) if s == "input" => VarClass::Input,
                Scalar::Str(s) if s == "output" => VarClass::Output,
                Scalar::Str(s) if s == "memory" => VarClass::Memory,
                Scalar::Str(s) => {
                    let kind = Invalid::Shape {
                        expected: "\"input\", \"output\" or \"memory\"",
                        found: format!("\"{s}\""),
                    };
                    problem.get_or_insert_with(|| Problem::new(".class", o, kind));
                    VarClass::Default
                }
                other => {
                    let kind = shape("a string", &other);
                    problem.get_or_insert_with(|| Problem::new(".class", o, kind));
                    VarClass::Default
                }
            };
            var.class = Located { value, origin: o };
        }
        var.problem = problem;
        Ok(var)
    }
}

/// The body of a POU: `rungs` or `fbd`, not both (`origin`: of the POU object).
fn body<'a>(
    rungs: Option<Part<Option<Vec<syntax::Rung<'a>>>>>,
    fbd: Option<syntax::FbdBody<'a>>,
    path: &str,
    what: &'static str,
    origin: Origin,
    problems: &mut Vec<Problem>,
) -> Option<Body<'a>> {
    match (rungs, fbd) {
        (Some(_), Some(f)) => {
            problems.push(Problem {
                at: join(path, "fbd"),
                origin: f.origin,
                kind: Invalid::Misplaced {
                    what: "`fbd`",
                    place: "together with `rungs` (a body is one of them)",
                },
            });
            None
        }
        (None, Some(f)) => Some(Body::Fbd(f)),
        (Some(r), None) => {
            problems.extend(r.problems);
            r.value.map(Body::Rungs)
        }
        (None, None) => {
            problems.push(Problem {
                at: path.to_owned(),
                origin,
                kind: Invalid::MissingField {
                    field: "rungs",
                    what,
                },
            });
            None
        }
    }
}
