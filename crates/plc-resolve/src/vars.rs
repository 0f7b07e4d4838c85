//! Variable declarations (`vars`, and a function block's `inputs`/`outputs`/`vars`): names,
//! types, classes, initial values; instances of user function blocks are recorded for later.

use super::util::check_var_name;
use super::{Builder, InstanceDraft, Result};
use crate::operand;
use plc_diag::{Invalid, LoadError};
use plc_model::*;
use plc_syntax as syntax;

impl<'a> Builder<'a> {
    /// Declares the variables of a scope: the program's (`scope` None) or a POU's, whose display
    /// names get the prefix (`SBR:`, or `G1.` for an instance). `elementary`: only BOOL, INT,
    /// DINT, REAL, TIME (inputs and outputs of function blocks). Variables of a user function block
    /// type are instances: recorded in `pending`, given their POU by [`Self::expand`]. Every
    /// declaration's problem is reported; the others are still declared.
    pub(super) fn declare_vars(
        &mut self,
        vars: &[syntax::Var],
        path: &str,
        scope: Option<(PouId, String)>,
        elementary: bool,
    ) {
        // How far ahead the program's table slot of a name is prefetched: each insert into a
        // table of a million names is a cache miss, and this overlaps them (a hint only).
        const AHEAD: usize = 8;
        for (i, v) in vars.iter().enumerate() {
            if let (None, Some(next)) = (&scope, vars.get(i + AHEAD)) {
                self.globals.prefetch(next.name.as_str());
            }
            // The declaration's path, rendered only for an error.
            let p = || format!("{path}[{i}]");
            let r = self.declare_var(v, &p, &scope, elementary);
            if let Err(e) = r {
                self.report(e.at(v.origin));
            }
        }
    }

    fn declare_var(
        &mut self,
        v: &syntax::Var,
        p: &dyn Fn() -> String,
        scope: &Option<(PouId, String)>,
        elementary: bool,
    ) -> Result<()> {
        if let Some(problem) = &v.problem {
            return Err(LoadError::invalid(
                None,
                &format!("{}{}", p(), problem.at),
                problem.kind.clone(),
            )
            .at(problem.origin));
        }
        let name: &str = v.name.as_str();
        check_var_name(name, || format!("{}.name", p())).map_err(|e| e.at(v.name.origin))?;
        let tname: &str = v.ty.as_str();
        let user_fb = Type::parse(tname).is_none() && self.fb_index.contains_key(tname);
        // A misspelt type (`bool`, `INTT`): the nearest of the types the program can name.
        let type_hint = || {
            let standard = plc_model::ELEMENTARY.iter().map(|&(n, _)| n).chain([
                "TIME", "TON", "TOF", "TP", "CTU", "CTD", "SR", "RS", "R_TRIG", "F_TRIG", "CTUD",
            ]);
            let user = self.fb_types.iter().map(|f| f.name.as_str());
            plc_diag::suggest::did_you_mean(tname, standard.chain(user))
        };
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
                let e = LoadError::invalid(
                    None,
                    &format!("{}.type", p()),
                    Invalid::UnknownTypeOrFb {
                        name: tname.into(),
                        fbs,
                    },
                )
                .at(v.ty.origin);
                return Err(match type_hint() {
                    Some(h) => e.with_hint(&h),
                    None => e,
                });
            }
            None => {
                let e = LoadError::invalid(
                    None,
                    &format!("{}.type", p()),
                    Invalid::UnknownType { name: tname.into() },
                )
                .at(v.ty.origin);
                return Err(match type_hint() {
                    Some(h) => e.with_hint(&h),
                    None => e,
                });
            }
        };
        // Only an elementary variable may have a dotted name (a structure's field).
        if name.contains('.') && matches!(ty, Type::Fb(_)) {
            return Err(LoadError::invalid(
                None,
                &format!("{}.name", p()),
                Invalid::BadName { name: name.into() },
            )
            .at(v.name.origin));
        }
        if elementary && matches!(ty, Type::Fb(_)) {
            return Err(LoadError::invalid(
                None,
                &format!("{}.type", p()),
                Invalid::Misplaced {
                    what: "a function block type",
                    place:
                        "as an input or output of a function block (declare the instance in `vars`)",
                },
            )
            .at(v.ty.origin));
        }
        let class = match v.class.value {
            // A function block instance declared in a program's VAR_INPUT or VAR_OUTPUT (an
            // OpenPLC project's `CTU1` in `inputVars`): nothing passes a program an instance
            // (the configuration calls it without arguments), so, as in matiec, it is the
            // program's own instance, called where the body calls it.
            _ if matches!(ty, Type::Fb(_)) => VarClass::Memory,
            syntax::VarClass::Input => VarClass::Input,
            syntax::VarClass::Output => VarClass::Output,
            syntax::VarClass::Memory | syntax::VarClass::Default => VarClass::Memory,
        };
        let init = match &v.init {
            None => ty.zero(),
            Some(j) if matches!(ty, Type::Fb(_)) => {
                return Err(LoadError::invalid(
                    None,
                    &format!("{}.init", p()),
                    Invalid::Misplaced {
                        what: "`init`",
                        place: "on a function block instance",
                    },
                )
                .at(j.origin))
            }
            Some(init) => {
                let ip = format!("{}.init", p());
                let j = &init.value;
                let fail = |k| LoadError::invalid(None, &ip, k).at(init.origin);
                let u = operand::parse(j, &|n| {
                    Err(Invalid::Shape {
                        expected: "a constant",
                        found: format!("name \"{n}\""),
                    })
                })
                .map_err(fail)?;
                match operand::typed(&u, ty, "the initial value", &j.json()) {
                    Ok(Operand::Const(v)) => v,
                    Ok(Operand::Var(_)) => {
                        return Err(fail(Invalid::Shape {
                            expected: "a constant",
                            found: j.kind(),
                        }))
                    }
                    Err(k) => return Err(fail(k)),
                }
            }
        };
        // A plain name that is the first part of declared dotted names (a structure's fields).
        let scope_key = scope.as_ref().map(|(p, _)| *p);
        let structure = !self.structure_roots.is_empty()
            && !name.contains('.')
            && self.structure_roots.contains(&(scope_key, name.to_owned()));
        let (table, instances) = match scope {
            None => (&mut self.globals, &mut self.global_instances),
            Some((p, _)) => (
                &mut self.locals[p.index()],
                &mut self.local_instances[p.index()],
            ),
        };
        // A dotted name whose first part is a variable or an instance of the scope would hide
        // its field or member (`T1.Q`), and the other way round: both are declared twice.
        let root = name.split_once('.').map(|(r, _)| r);
        let hides = root.is_some_and(|r| table.contains_key(r) || instances.contains_key(r));
        if table.contains_key(name) || instances.contains_key(name) || hides || structure {
            return Err(LoadError::invalid(
                None,
                &format!("{}.name", p()),
                Invalid::DuplicateVar { name: name.into() },
            )
            .at(v.name.origin));
        }
        let display = match scope {
            None => name.to_owned(),
            Some((_, prefix)) => format!("{prefix}{name}"),
        };
        if user_fb {
            let idx = self.instances.len();
            instances.insert(name, idx);
            self.instances.push(InstanceDraft {
                display,
                fb: tname.to_owned(),
                path: p(),
                origin: v.origin,
                name_origin: v.name.origin,
                pou: None,
                inputs: Vec::new(),
                outputs: Vec::new(),
            });
            self.pending.push(idx);
            return Ok(());
        }
        let id = VarId(self.vars.len() as u32);
        table.insert(name, id);
        if let Some(root) = root {
            self.structure_roots.insert((scope_key, root.to_owned()));
        }
        self.vars.push(Var {
            name: display,
            ty,
            class,
            init,
            scope: scope.as_ref().map(|(p, _)| *p),
            hidden: false,
        });
        Ok(())
    }
}
