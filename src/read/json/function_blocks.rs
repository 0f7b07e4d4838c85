//! User function blocks: reading the `function_blocks` types (signatures, declarations, no
//! recursion, bodies) and expanding each instance into its own POU.

use super::util::{array, check_keys, check_name, object};
use super::{Builder, FbType, PouDraft, Result};
use crate::fbd::read::FbSig;
use crate::fbd::FbdPouKind;
use crate::model::*;
use crate::read::error::{Invalid, LoadError};
use serde_json::Value as Json;
use std::collections::HashMap;

impl<'a> Builder<'a> {
    /// Reads `function_blocks`: names and pins first (bodies may use each other), then each
    /// type's declarations (checked on a scratch scope), its body and, for FBD, its networks.
    pub(super) fn function_block_types(&mut self, fbs: &'a Json) -> Result<()> {
        let fbs = object(fbs, "function_blocks", None, "the function blocks")?;
        for (fname, body) in fbs {
            let path = format!("function_blocks.{fname}");
            check_name(fname, &path, None)?;
            if Type::parse(fname).is_some() {
                return Err(LoadError::invalid(
                    None,
                    &path,
                    Invalid::Misplaced {
                        what: "a function block named like a standard type",
                        place: "(rename it)",
                    },
                ));
            }
            let o = object(body, &path, None, "a function block")?;
            check_keys(
                o,
                &["vars", "inputs", "outputs", "fbd", "rungs", "comment"],
                "a function block",
                &path,
                None,
            )?;
            let names = |k: &str| -> Vec<String> {
                o.get(k)
                    .and_then(Json::as_array)
                    .into_iter()
                    .flatten()
                    .filter_map(|v| v.get("name").and_then(Json::as_str).map(str::to_owned))
                    .collect()
            };
            let sig = FbSig {
                inputs: names("inputs"),
                outputs: names("outputs"),
            };
            self.fb_index.insert(fname.clone(), self.fb_types.len());
            self.fb_types.push(FbType {
                name: fname.clone(),
                path,
                inputs: o.get("inputs"),
                outputs: o.get("outputs"),
                vars: o.get("vars"),
                rungs: None,
                fbd: None,
                sig,
            });
        }
        // Declarations on a scratch scope (rolled back), and which types each type instantiates.
        let mut uses: Vec<Vec<(usize, String)>> = Vec::new();
        for f in 0..self.fb_types.len() {
            let (vars_mark, inst_mark) = (self.vars.len(), self.instances.len());
            let scratch = PouId(self.locals.len() as u32);
            self.locals.push(HashMap::new());
            self.local_instances.push(HashMap::new());
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
                if let Some(d) = decl {
                    self.declare_vars(
                        d,
                        &format!("{path}.{key}"),
                        Some((scratch, prefix.clone())),
                        elementary,
                    )?;
                }
            }
            uses.push(
                self.instances[inst_mark..]
                    .iter()
                    .map(|i| (self.fb_index[&i.fb], i.path.clone()))
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
                if let Some((g, p)) = uses[f].get(*i) {
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
                        ));
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
        for f in 0..self.fb_types.len() {
            let path = self.fb_types[f].path.clone();
            let o = fbs[&self.fb_types[f].name]
                .as_object()
                .expect("checked above");
            match (o.get("rungs"), o.get("fbd")) {
                (Some(_), Some(_)) => {
                    return Err(LoadError::invalid(
                        None,
                        &format!("{path}.fbd"),
                        Invalid::Misplaced {
                            what: "`fbd`",
                            place: "together with `rungs` (a body is one of them)",
                        },
                    ))
                }
                (Some(r), None) => {
                    self.fb_types[f].rungs = Some(array(r, &format!("{path}.rungs"), None)?)
                }
                (None, Some(j)) => {
                    let index = &self.fb_index;
                    let types = &self.fb_types;
                    let sig = |n: &str| index.get(n).map(|&i| types[i].sig.clone());
                    let body = crate::fbd::read::read_body(
                        j,
                        &format!("{path}.fbd"),
                        &self.fb_types[f].name,
                        FbdPouKind::FunctionBlock,
                        &sig,
                    )?;
                    self.fb_types[f].fbd = Some(self.fbd_bodies.len());
                    self.fbd_bodies.push(body);
                }
                (None, None) => {
                    return Err(LoadError::invalid(
                        None,
                        &path,
                        Invalid::MissingField {
                            field: "fbd` or `rungs",
                            what: "a function block",
                        },
                    ))
                }
            }
        }
        Ok(())
    }

    /// Gives instance `idx` its POU: the function block's variables declared as `G1.name`, its
    /// body (ladder rungs now, FBD lowered later), nested instances right after it.
    pub(super) fn expand(&mut self, idx: usize, stack: &mut Vec<String>) -> Result<()> {
        let f = self.fb_index[&self.instances[idx].fb];
        let (display, ipath) = (
            self.instances[idx].display.clone(),
            self.instances[idx].path.clone(),
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
            ));
        }
        if self.pous.iter().any(|p| p.name == display) {
            return Err(LoadError::invalid(
                None,
                &format!("{ipath}.name"),
                Invalid::Misplaced {
                    what: "a function block instance named like the program or a subroutine",
                    place: "(rename one of them)",
                },
            ));
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
        draft.rungs = rungs.map(|r| r.iter().collect()).unwrap_or_default();
        draft.fbd = fbd;
        draft.prefix = format!("{display}:");
        draft.var_prefix = format!("{display}.");
        draft.callable = false;
        self.pous.push(draft);
        self.locals.push(HashMap::new());
        self.local_instances.push(HashMap::new());
        let mark = self.pending.len();
        let prefix = format!("{display}.");
        for (key, decl, elementary) in [
            ("inputs", inputs, true),
            ("outputs", outputs, true),
            ("vars", vars, false),
        ] {
            if let Some(d) = decl {
                self.declare_vars(
                    d,
                    &format!("{path}.{key}"),
                    Some((pou, prefix.clone())),
                    elementary,
                )?;
            }
        }
        let locals = &self.locals[pou.index()];
        let pins = |names: &[String]| {
            names
                .iter()
                .map(|n| (n.clone(), locals[n]))
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
