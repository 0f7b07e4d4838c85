//! Resolving the main program's rungs as the reader reads them ([`Stream`], a
//! [`syntax::RungSink`]), so that a million rungs are never held as syntax: each is resolved
//! into the model and dropped, and the memory of its syntax is reused for the next.
//!
//! It is a fast path with an exact fallback. The stream takes the rungs only when the reader
//! offers them (the program's variables read, nothing malformed before the rung array, no
//! function block types); it declares the variables then, and resolves each rung with the same
//! functions as the whole-tree resolver. Anything it cannot do in file order it does at the
//! end: a rung with a jump or a call (whose label or subroutine may come later), a FOR or a
//! NEXT (made with its partner's id, which needs them all) is *held* — its
//! syntax kept, its edge-contact memories made in advance so that variables keep their order —
//! and resolved once the whole file is read. The edge memories of the streamed rungs are moved
//! after the variables declared later (subroutine locals, instances), as the whole-tree
//! resolver numbers them: the model is identical. On the first problem of any kind the stream
//! gives up and [`Stream::finish`] says so: the caller then reads the text again and resolves
//! the whole tree, which reports every error exactly as it always has. Errors never come from
//! here.

use super::elements::edge_var;
use super::structure::{loop_end, Loops};
use super::table::{IndexSet, NameTable};
use super::util::{check_label, FastMap};
use super::Builder;
use plc_fbd::Fbd;
use plc_model::*;
use plc_syntax as syntax;

/// The main program's rungs resolved while they were read.
#[derive(Default)]
pub(super) struct Streamed<'a> {
    /// In file order; a held rung's series is empty until [`Builder::settle`].
    pub(super) rungs: Arena<RungId, Rung>,
    pub(super) held: Vec<Held<'a>>,
    /// The rung ids, by their index in `rungs`.
    pub(super) ids: IndexSet,
    /// Labels of the main program.
    pub(super) labels: FastMap<String, RungId>,
    /// The main program's declared variables (edge memories follow them while reading).
    pub(super) declared: usize,
    /// The edge memories, split off once the file is read: they go after every other variable.
    pub(super) edges: Vec<Var>,
}

/// A rung resolved at the end: its index, its syntax and its first edge memory (numbered as
/// while reading).
pub(super) struct Held<'a> {
    index: usize,
    rung: syntax::Rung<'a>,
    edges: VarId,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum State {
    /// No rungs offered (yet): the tree has them.
    Idle,
    Streaming,
    /// Rungs were taken, then something could not be resolved (a declaration, a rung, a
    /// second rung array): only the whole tree will do.
    GaveUp,
}

/// How many rungs are read before they are resolved: enough that the table lookups of a batch
/// overlap their cache misses (see [`Stream::resolve_batch`]), few enough to stay in the cache.
const BATCH: usize = 16;

/// The resolver as a [`syntax::RungSink`] for text `'t`.
pub struct Stream<'t> {
    b: Builder<'t>,
    state: State,
    /// Rungs read and not yet resolved (fewer than [`BATCH`]).
    batch: Vec<syntax::Rung<'t>>,
}

impl Default for Stream<'_> {
    fn default() -> Self {
        Stream {
            b: Builder::default(),
            state: State::Idle,
            batch: Vec::with_capacity(BATCH),
        }
    }
}

impl<'t> syntax::RungSink<'t> for Stream<'t> {
    fn start(&mut self, vars: Vec<syntax::Var<'t>>, rungs: usize) {
        if self.state != State::Idle {
            // A second rung array: the last one counts, so the first must not have been taken.
            self.state = State::GaveUp;
            return;
        }
        self.b.declare_main(String::new(), &vars);
        drop(vars);
        if !self.b.errors.is_empty() || !self.b.pending.is_empty() {
            self.state = State::GaveUp;
            return;
        }
        self.b.streamed = Some(Streamed {
            declared: self.b.vars.len(),
            // Sized up front: a million rungs would otherwise be moved twenty times.
            rungs: Arena::with_capacity(rungs),
            ids: IndexSet::with_capacity(rungs),
            ..Streamed::default()
        });
        self.state = State::Streaming;
    }

    fn retract(&mut self) {
        if self.state == State::Streaming {
            self.state = State::GaveUp;
        }
    }

    fn rung(&mut self, rung: syntax::Rung<'t>) {
        if self.state == State::Streaming {
            self.batch.push(rung);
            if self.batch.len() == BATCH {
                self.resolve_batch();
            }
        }
    }
}

impl<'t> Stream<'t> {
    /// Resolves the rungs read so far, in file order. In a program of a million rungs and
    /// variables every name lookup is a cache miss (the tables are tens of megabytes, and a
    /// hash spreads the names over them), so the table slots of the whole batch's rung ids and
    /// contact and coil names are prefetched first: their misses overlap instead of coming one
    /// after another (a third of the time spent loading a million rungs, `perf record`).
    fn resolve_batch(&mut self) {
        let mut batch = std::mem::take(&mut self.batch);
        if let Some(s) = &self.b.streamed {
            for r in &batch {
                s.ids.prefetch(r.id.as_str());
                prefetch_names(&self.b.globals, &r.ld);
            }
        }
        for r in batch.drain(..) {
            if self.state == State::Streaming && self.b.stream_rung(r).is_none() {
                self.state = State::GaveUp;
            }
        }
        self.batch = batch;
    }

    /// True when the tree lacks the main program's rungs (the stream took them).
    pub fn took_rungs(&self) -> bool {
        matches!(self.state, State::Streaming | State::GaveUp)
    }

    /// The program, resolved from the streamed rungs and the rest of the tree `syn` (read from
    /// the same text); `None` when the stream gave up, or anything in the file is not right:
    /// then only resolving the whole tree (read again) gives the program or its errors.
    pub fn finish<'s>(mut self, syn: &'s syntax::Program<'t>) -> Option<(Program, Fbd)> {
        self.resolve_batch();
        let empty_body = matches!(&syn.body, Some(syntax::Body::Rungs(r)) if r.is_empty());
        if self.state != State::Streaming
            || !syn.vars.is_empty()
            || !empty_body
            || !syn.problems.is_empty()
            || !syn.function_blocks.is_empty()
            || syn.name.contains(char::is_control)
        {
            return None;
        }
        let mut b: Builder<'s> = self.b;
        b.pous[0].name = syn.name.to_string();
        if let Some(s) = b.streamed.as_mut() {
            s.edges = b.vars.split_off(s.declared);
        }
        b.declare_subroutines(syn);
        b.resolve_declared(syn).ok()
    }
}

impl<'a> Builder<'a> {
    /// Pass 1 and 2 of the resolver for one rung of the main program, as read; `None` for
    /// anything that is not right (the whole-tree resolver will say what).
    fn stream_rung(&mut self, r: syntax::Rung<'a>) -> Option<()> {
        let s = self.streamed.as_mut()?;
        let index = s.rungs.len();
        let text = |i: u32| s.rungs[i as usize].id.as_str();
        let printable = !r.id.as_str().contains(char::is_control);
        if r.problem.is_some() || !printable || !s.ids.insert(r.id.as_str(), index as u32, text) {
            return None;
        }
        let id = r.id.value.to_string();
        if let Some(l) = &r.label {
            check_label(l.as_str(), String::new, None).ok()?;
            if s.labels
                .insert(l.value.to_string(), s.rungs.next_id())
                .is_some()
            {
                return None;
            }
        }
        let mut rung = Rung {
            id,
            label: r.label.as_ref().map(|l| l.value.to_string()),
            comment: r.comment.as_ref().map(|c| c.to_string()),
            pou: self.pous.id(0),
            series: Vec::new(),
            lowered: None,
            origin: r.origin,
        };
        if refers_ahead(&r.ld) || loop_end(&r.ld).is_some() {
            let edges = self.vars.next_id();
            for k in 1..=edge_contacts(&r.ld) {
                self.vars.push(edge_var(&rung.id, k));
            }
            let s = self.streamed.as_mut()?;
            s.rungs.push(rung);
            s.held.push(Held {
                index,
                rung: r,
                edges,
            });
            return Some(());
        }
        let main = self.pous.id(0);
        rung.series = (self.ladder_series(main, ("", index), &r, &rung.id, None)).ok()?;
        self.streamed.as_mut()?.rungs.push(rung);
        Some(())
    }

    /// The streamed rungs, completed now that every declaration is made: their edge memories
    /// after all other variables, the held rungs resolved.
    pub(super) fn settle(
        &mut self,
        s: Streamed<'a>,
        loops: &mut Loops,
    ) -> super::Result<Vec<Rung>> {
        loops.pair_pou(s.held.iter().filter_map(|h| {
            let end = loop_end(&h.rung.ld)?;
            Some((s.rungs.id(h.index), end, h.rung.ld.len()))
        }));
        let offset = (self.vars.len() - s.declared) as u32;
        self.vars.extend(s.edges);
        let mut rungs = s.rungs;
        if offset > 0 {
            for r in rungs.iter_mut() {
                relocate_edges(&mut r.series, offset);
            }
        }
        for h in s.held {
            self.edge_reserved = Some(Numbering::starting_at(h.edges.shifted(offset)));
            let id = std::mem::take(&mut rungs[h.index].id);
            let partner = loops.partner(rungs.id(h.index));
            let main = self.pous.id(0);
            let series = self.ladder_series(main, ("", h.index), &h.rung, &id, partner);
            self.edge_reserved = None;
            rungs[h.index].id = id;
            rungs[h.index].series = series?;
        }
        Ok(rungs.into_vec())
    }
}

/// Prefetches the table slots of the contacts' and coils' names of `series` (see
/// [`NameTable::prefetch`]); other operands are looked up without.
fn prefetch_names(table: &NameTable<VarId>, series: &[syntax::Element]) {
    use syntax::ElementKind as K;
    for e in series {
        match &e.kind {
            K::Contact { var, .. } | K::Coil { var, .. } | K::Set(var) | K::Reset(var) => {
                table.prefetch(var.as_str())
            }
            K::Or(bs) | K::Branch(bs) => bs.iter().for_each(|b| prefetch_names(table, b)),
            _ => {}
        }
    }
}

/// True when the series jumps or calls (its label or subroutine may be read later).
fn refers_ahead(series: &[syntax::Element]) -> bool {
    use syntax::ElementKind as K;
    series.iter().any(|e| match &e.kind {
        K::Jmp(_) | K::Call(_) => true,
        K::Or(bs) | K::Branch(bs) => bs.iter().any(|b| refers_ahead(b)),
        _ => false,
    })
}

/// The number of edge contacts in the series (each gets one hidden memory).
fn edge_contacts(series: &[syntax::Element]) -> u32 {
    use syntax::ElementKind as K;
    series
        .iter()
        .map(|e| match &e.kind {
            K::Contact { edge: Some(_), .. } => 1,
            K::Or(bs) | K::Branch(bs) => bs.iter().map(|b| edge_contacts(b)).sum(),
            _ => 0,
        })
        .sum()
}

/// Moves the edge memories the series reads by `offset` variables.
fn relocate_edges(series: &mut [Element], offset: u32) {
    for e in series {
        match e {
            Element::Contact {
                kind: ContactKind::Rising { memory } | ContactKind::Falling { memory },
                ..
            } => *memory = memory.shifted(offset),
            Element::Or(bs) | Element::Branch(bs) => {
                for b in bs {
                    relocate_edges(b, offset);
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plc_synth::{generate_string, GenConfig};

    /// The program by the stream (which must have taken and resolved the rungs) and by the
    /// whole tree, as `Debug` text of both models.
    fn both(text: &str) -> (String, String) {
        let mut stream = Stream::default();
        let syn = plc_read::json::parse_with(text, Some(&mut stream)).expect("parses");
        assert!(stream.took_rungs(), "the stream takes the rungs");
        let streamed = stream.finish(&syn).expect("the stream resolves it");
        let syn = plc_read::json::parse(text).expect("parses");
        let whole = super::super::resolve(text, &syn).expect("resolves");
        (
            format!("{:?}", (&streamed.0, &streamed.1.pous.len())),
            format!("{:?}", (&whole.0, &whole.1.pous.len())),
        )
    }

    #[test]
    fn streamed_rungs_resolve_to_the_same_model_as_the_whole_tree() {
        // Edge contacts before, in and after rungs held for a forward jump and a call, and
        // subroutine locals declared after the main rungs (the edge memories go after them).
        let text = r#"{"program": "P", "vars": [
            {"name": "A", "type": "BOOL"}, {"name": "B", "type": "BOOL"}],
          "rungs": [
            {"id": "R1", "ld": [{"contact": "A", "edge": "rising"}, {"coil": "B"}]},
            {"id": "R2", "ld": [{"contact": "B", "edge": "falling"},
                                {"or": [[{"contact": "A", "edge": "rising"}]]}, {"jmp": "L"}]},
            {"id": "R3", "ld": [{"contact": "A", "edge": "rising"}, {"call": "S"}]},
            {"id": "R4", "label": "L", "ld": [{"contact": "A", "edge": "falling"}, {"coil": "B"}]}],
          "subroutines": {"S": {"vars": [{"name": "X", "type": "BOOL"}],
            "rungs": [{"id": "S1", "ld": [{"contact": "X", "edge": "rising"}, {"coil": "X"}]}]}}}"#;
        let (streamed, whole) = both(text);
        assert!(streamed.contains("R2:edge2") && streamed.contains("S:X"));
        assert_eq!(streamed, whole);
        for rungs in [1, 200, 3000] {
            let text = generate_string(&GenConfig::all_features(rungs, 50, 7));
            let (streamed, whole) = both(&text);
            assert_eq!(streamed, whole, "{rungs} rungs");
        }
    }

    #[test]
    fn the_stream_gives_up_on_any_problem() {
        let gives_up = [
            r#"{"program": "P", "vars": [], "rungs": [{"id": "R1", "ld": [{"coil": "Z"}]}]}"#,
            r#"{"program": "P", "vars": [{"name": "A", "type": "BOOL"}],
                "rungs": [{"id": "R1", "ld": [{"coil": "A"}]}], "rungs": []}"#,
            r#"{"program": "P", "vars": [{"name": "A", "type": "BOOL"}],
                "rungs": [{"id": "R1", "ld": [{"coil": "A"}]}], "vars": []}"#,
            r#"{"program": "P", "vars": [{"name": "A", "type": "BOOL"}],
                "rungs": [{"id": "R1", "ld": [{"jmp": "NOWHERE"}]}]}"#,
            // A declaration that does not resolve: the rungs were taken all the same.
            r#"{"program": "P", "vars": [{"name": "A", "type": "NOPE"}],
                "rungs": [{"id": "R1", "ld": [{"coil": "A"}]}]}"#,
        ];
        for text in gives_up {
            let mut stream = Stream::default();
            let syn = plc_read::json::parse_with(text, Some(&mut stream)).expect("parses");
            assert!(stream.took_rungs(), "{text}");
            assert!(stream.finish(&syn).is_none(), "{text}");
        }
        // Not offered: something before the rungs is malformed; the tree keeps them.
        let kept = r#"{"program": "P", "vars": [{"name": "A", "type": "BOOL"}], "x": 1,
            "rungs": [{"id": "R1", "ld": [{"coil": "A"}]}]}"#;
        let mut stream = Stream::default();
        let syn = plc_read::json::parse_with(kept, Some(&mut stream)).expect("parses");
        assert!(!stream.took_rungs());
        assert!(matches!(&syn.body, Some(syntax::Body::Rungs(r)) if r.len() == 1));
    }
}
