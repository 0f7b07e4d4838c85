//! User function blocks: reading the `function_blocks` types (signatures, declarations, no
//! recursion, bodies) and expanding each instance into its own POU.

use super::table::NameTable;
use super::util::check_name;
use super::{Builder, FbType, PouDraft, Result};
use crate::diag::{Invalid, LoadError, Origin};
use crate::fbd::FbdPouKind;
use crate::model::*;
use crate::resolve::fbd_read::FbSig;
use crate::syntax;

impl<'a> Builder<'a> {
    /// Reads `function_blocks`: names and pins first (bodies may use each other), then each
    /// type's declarations (checked on a scratch scope), its body and, for FBD, its networks.
    pub(super) fn function_block_types(
        &mut self,
        fbs: &'a [syntax::FunctionBlock<'a>],
    ) -> Result<()> {
        let mut bodies = Vec::with_capacity(fbs.len());
        for fb in fbs {
            let path = format!("function_blocks.{}", fb.name);
            check_name(&fb.name, || path.clone(), None).map_err(|e| e.at(fb.origin))?;
            if Type::parse(&fb.name).is_some() {
                return Err(LoadError::invalid(
                    None,
                    &path,
                    Invalid::Misplaced {
                        what: "a function block named like a standard type",
                        place: "(rename it)",
                    },
                )
                .at(fb.origin));
            }
            let names = |vs: &[syntax::Var]| -> Vec<String> {
                vs.iter()
                    .filter(|v| v.problem.is_none())
                    .map(|v| v.name.value.to_string())
                    .collect()
            };
            let sig = FbSig {
                inputs: names(&fb.inputs),
                outputs: names(&fb.outputs),
            };
            self.fb_index
                .insert(fb.name.to_string(), self.fb_types.len());
            self.fb_types.push(FbType {
                name: fb.name.to_string(),
                path,
                inputs: &fb.inputs,
                outputs: &fb.outputs,
                vars: &fb.vars,
                rungs: None,
                fbd: None,
                sig,
            });
            bodies.push(&fb.body);
        }
        // Declarations on a scratch scope (rolled back), and which types each type instantiates.
        let mut uses: Vec<Vec<(usize, String, Origin)>> = Vec::new();
        for f in 0..self.fb_types.len() {
            let (vars_mark, inst_mark) = (self.vars.len(), self.instances.len());
            let scratch = PouId(self.locals.len() as u32);
            self.locals.push(NameTable::default());
            self.local_instances.push(NameTable::default());
            let (path, prefix) = (
                self.fb_types[f].path.clone(),
                format!("{}.", self.fb_types[f].name),
            );
            let decls = [
                ("inputs", self.fb_types[f].inputs, true),
                ("outputs", self.fb_types[f].outputs, true),
                ("vars", self.fb_types[f].vars, false),
            ];
            for (key, decl, elementary) in decls {
                self.declare_vars(
                    decl,
                    &format!("{path}.{key}"),
                    Some((scratch, prefix.clone())),
                    elementary,
                );
            }
            uses.push(
                self.instances[inst_mark..]
                    .iter()
                    .filter_map(|i| Some((*self.fb_index.get(&i.fb)?, i.path.clone(), i.origin)))
                    .collect(),
            );
            self.vars.truncate(vars_mark);
            self.instances.truncate(inst_mark);
            self.pending.clear();
            self.locals.pop();
            self.local_instances.pop();
        }
        // No type may contain itself (directly or through others).
        for start in 0..self.fb_types.len() {
            let mut seen = vec![false; self.fb_types.len()];
            seen[start] = true;
            let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
            while let Some(&mut (f, ref mut i)) = stack.last_mut() {
                if let Some((g, p, origin)) = uses[f].get(*i) {
                    *i += 1;
                    if *g == start {
                        let mut chain: Vec<&str> = stack
                            .iter()
                            .map(|&(x, _)| self.fb_types[x].name.as_str())
                            .collect();
                        chain.push(&self.fb_types[start].name);
                        return Err(LoadError::invalid(
                            None,
                            p,
                            Invalid::FbRecursion {
                                name: self.fb_types[start].name.clone(),
                                chain: chain.join(" → "),
                            },
                        )
                        .at(*origin));
                    }
                    if !seen[*g] {
                        seen[*g] = true;
                        stack.push((*g, 0));
                    }
                } else {
                    stack.pop();
                }
            }
        }
        // Bodies.
        for (f, body) in bodies.into_iter().enumerate() {
            let path = self.fb_types[f].path.clone();
            match body {
                None => {} // reported by the reader
                Some(syntax::Body::Rungs(r)) => self.fb_types[f].rungs = Some(r),
                Some(syntax::Body::Fbd(j)) => {
                    let name = self.fb_types[f].name.clone();
                    let body =
                        self.read_fbd(j, &format!("{path}.fbd"), &name, FbdPouKind::FunctionBlock)?;
                    self.fb_types[f].fbd = Some(self.fbd_bodies.len());
                    self.fbd_bodies.push(body);
                    self.fbd_origins.push(j.origin);
                }
            }
        }
        Ok(())
    }

    /// Gives instance `idx` its POU: the function block's variables declared as `G1.name`, its
    /// body (ladder rungs now, FBD lowered later), nested instances right after it.
    pub(super) fn expand(&mut self, idx: usize, stack: &mut Vec<String>) -> Result<()> {
        let Some(&f) = self.fb_index.get(&self.instances[idx].fb) else {
            return Ok(()); // declared only for user types (checked when declared)
        };
        let (display, ipath, iorigin) = (
            self.instances[idx].display.clone(),
            self.instances[idx].path.clone(),
            self.instances[idx].origin,
        );
        if stack.contains(&self.fb_types[f].name) {
            let mut chain = stack.clone();
            chain.push(self.fb_types[f].name.clone());
            return Err(LoadError::invalid(
                None,
                &ipath,
                Invalid::FbRecursion {
                    name: self.fb_types[f].name.clone(),
                    chain: chain.join(" → "),
                },
            )
            .at(iorigin));
        }
        if self.pous.iter().any(|p| p.name == display) {
            return Err(LoadError::invalid(
                None,
                &format!("{ipath}.name"),
                Invalid::Misplaced {
                    what: "a function block instance named like the program or a subroutine",
                    place: "(rename one of them)",
                },
            )
            .at(self.instances[idx].name_origin));
        }
        let pou = PouId(self.pous.len() as u32);
        let t = &self.fb_types[f];
        let (path, inputs, outputs, vars, rungs, fbd) =
            (t.path.clone(), t.inputs, t.outputs, t.vars, t.rungs, t.fbd);
        let mut draft = PouDraft::new(
            display.clone(),
            PouKind::Subroutine,
            format!("{path}.rungs"),
        );
        draft.rungs = rungs.unwrap_or_default();
        draft.fbd = fbd;
        draft.prefix = format!("{display}:");
        draft.var_prefix = format!("{display}.");
        draft.callable = false;
        self.pous.push(draft);
        self.locals.push(NameTable::default());
        self.local_instances.push(NameTable::default());
        let mark = self.pending.len();
        let prefix = format!("{display}.");
        for (key, decl, elementary) in [
            ("inputs", inputs, true),
            ("outputs", outputs, true),
            ("vars", vars, false),
        ] {
            self.declare_vars(
                decl,
                &format!("{path}.{key}"),
                Some((pou, prefix.clone())),
                elementary,
            );
        }
        self.phase_end()?;
        let locals = &self.locals[pou.index()];
        let pins = |names: &[String]| {
            names
                .iter()
                .filter_map(|n| Some((n.clone(), *locals.get(n)?)))
                .collect::<Vec<_>>()
        };
        let (ins, outs) = (
            pins(&self.fb_types[f].sig.inputs),
            pins(&self.fb_types[f].sig.outputs),
        );
        let inst = &mut self.instances[idx];
        inst.pou = Some(pou);
        inst.inputs = ins;
        inst.outputs = outs;
        stack.push(self.fb_types[f].name.clone());
        let nested: Vec<usize> = self.pending.drain(mark..).collect();
        for n in nested {
            self.expand(n, stack)?;
        }
        stack.pop();
        Ok(())
    }
}
