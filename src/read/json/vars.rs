//! Variable declarations (`vars`, and a function block's `inputs`/`outputs`/`vars`): names,
//! types, classes, initial values; instances of user function blocks are recorded for later.

use super::util::{array, check_keys, check_name, object, required, string};
use super::{Builder, InstanceDraft, Result};
use crate::model::*;
use crate::read::error::{Invalid, LoadError};
use crate::read::operand;
use serde_json::Value as Json;

impl<'a> Builder<'a> {
    /// Declares the variables of a scope: the program's (`scope` None) or a POU's, whose display
    /// names get the prefix (`SBR:`, or `G1.` for an instance). `elementary`: only BOOL, INT,
    /// DINT, REAL, TIME (inputs and outputs of function blocks). Variables of a user function block
    /// type are instances: recorded in `pending`, given their POU by [`Self::expand`].
    pub(super) fn declare_vars(
        &mut self,
        vars: &Json,
        path: &str,
        scope: Option<(PouId, String)>,
        elementary: bool,
    ) -> Result<()> {
        for (i, v) in array(vars, path, None)?.iter().enumerate() {
            let p = format!("{path}[{i}]");
            let o = object(v, &p, None, "a variable")?;
            check_keys(
                o,
                &["name", "type", "class", "init", "comment"],
                "a variable",
                &p,
                None,
            )?;
            let name = string(
                required(o, "name", "a variable", &p, None)?,
                &format!("{p}.name"),
                None,
            )?;
            check_name(name, &format!("{p}.name"), None)?;
            let tname = string(
                required(o, "type", "a variable", &p, None)?,
                &format!("{p}.type"),
                None,
            )?;
            let user_fb = Type::parse(tname).is_none() && self.fb_index.contains_key(tname);
            let ty = match Type::parse(tname) {
                Some(t) => t,
                None if user_fb => Type::Fb(FbKind::Ton), // placeholder: instances are not variables
                None if !self.fb_types.is_empty() => {
                    let fbs = self
                        .fb_types
                        .iter()
                        .map(|f| f.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ");
                    return Err(LoadError::invalid(
                        None,
                        &format!("{p}.type"),
                        Invalid::UnknownTypeOrFb {
                            name: tname.into(),
                            fbs,
                        },
                    ));
                }
                None => {
                    return Err(LoadError::invalid(
                        None,
                        &format!("{p}.type"),
                        Invalid::UnknownType { name: tname.into() },
                    ))
                }
            };
            if elementary && matches!(ty, Type::Fb(_)) {
                return Err(LoadError::invalid(None, &format!("{p}.type"), Invalid::Misplaced {
                    what: "a function block type",
                    place: "as an input or output of a function block (declare the instance in `vars`)",
                }));
            }
            let class = match o.get("class") {
                None => VarClass::Memory,
                Some(c) => match string(c, &format!("{p}.class"), None)? {
                    "input" => VarClass::Input,
                    "output" => VarClass::Output,
                    "memory" => VarClass::Memory,
                    other => {
                        return Err(LoadError::invalid(
                            None,
                            &format!("{p}.class"),
                            Invalid::Shape {
                                expected: "\"input\", \"output\" or \"memory\"",
                                found: format!("\"{other}\""),
                            },
                        ))
                    }
                },
            };
            if matches!(ty, Type::Fb(_)) && class != VarClass::Memory {
                return Err(LoadError::invalid(
                    None,
                    &format!("{p}.class"),
                    Invalid::Misplaced {
                        what: "an input or output class",
                        place: "on a function block instance",
                    },
                ));
            }
            let init = match o.get("init") {
                None => ty.zero(),
                Some(_) if matches!(ty, Type::Fb(_)) => {
                    return Err(LoadError::invalid(
                        None,
                        &format!("{p}.init"),
                        Invalid::Misplaced {
                            what: "`init`",
                            place: "on a function block instance",
                        },
                    ))
                }
                Some(j) => {
                    let ip = format!("{p}.init");
                    let u = operand::parse(j, &|n| {
                        Err(Invalid::Shape {
                            expected: "a constant",
                            found: format!("name \"{n}\""),
                        })
                    })
                    .map_err(|k| LoadError::invalid(None, &ip, k))?;
                    match operand::typed(&u, ty, "the initial value", &j.to_string()) {
                        Ok(Operand::Const(v)) => v,
                        Ok(Operand::Var(_)) => unreachable!("constants only"),
                        Err(k) => return Err(LoadError::invalid(None, &ip, k)),
                    }
                }
            };
            let (table, instances) = match &scope {
                None => (&mut self.globals, &mut self.global_instances),
                Some((p, _)) => (
                    &mut self.locals[p.index()],
                    &mut self.local_instances[p.index()],
                ),
            };
            if table.contains_key(name) || instances.contains_key(name) {
                return Err(LoadError::invalid(
                    None,
                    &format!("{p}.name"),
                    Invalid::DuplicateVar { name: name.into() },
                ));
            }
            let display = match &scope {
                None => name.to_owned(),
                Some((_, prefix)) => format!("{prefix}{name}"),
            };
            if user_fb {
                let idx = self.instances.len();
                instances.insert(name.to_owned(), idx);
                self.instances.push(InstanceDraft {
                    display,
                    fb: tname.to_owned(),
                    path: p,
                    pou: None,
                    inputs: Vec::new(),
                    outputs: Vec::new(),
                });
                self.pending.push(idx);
                continue;
            }
            let id = VarId(self.vars.len() as u32);
            table.insert(name.to_owned(), id);
            self.vars.push(Var {
                name: display,
                ty,
                class,
                init,
                scope: scope.as_ref().map(|(p, _)| *p),
                hidden: false,
            });
        }
        Ok(())
    }
}
