//! Evaluation of linked `.cal` expressions with `f64`.
//!
//! Semantics follow `src/common/calexpr.c` and `calfunc.c` as the installed Radiance 6
//! behaves (checked with `rcalc`): division by zero gives 0 (with a warning in Radiance),
//! `^` is C's `pow` (so `0^-1` is infinite), function arguments are evaluated when the body
//! first needs them (so `if` only evaluates the branch it takes and recursion through `if`
//! terminates), and a function may receive another function's name as an argument and call
//! it (`dot(v1, v2) : v1(1)*v2(1) + ...` in rayinit.cal).
//!
//! Evaluation is pure: nothing is cached between calls and no global state is touched, so
//! one [`super::Program`] can be shared by every thread of a render. Runaway recursion
//! (`x = x + 1`) is stopped at [`MAX_EVAL_DEPTH`] nested evaluations with an error naming
//! the definition, and recursion that branches (`f(x) = if(x, f(x-1) + f(x-1), 1)`, whose
//! depth stays small while its calls double per level) at [`MAX_EVAL_CALLS`] evaluations of
//! definitions. Radiance has neither bound: it overflows its stack or runs for ever.

use std::cell::Cell;

use super::library::Lib;
use super::parse::Op;
use crate::error::{Error, Location};

/// Deepest evaluation nesting (expression levels plus calls) before giving up.
pub const MAX_EVAL_DEPTH: usize = 1000;

/// Most evaluations of definitions (variables and function calls) in one evaluation before
/// giving up: a million. The patterns and `rcalc` expressions in use evaluate a few dozen
/// per ray or record; one that needed a million per ray would make a render take days.
/// Fuzzing found that `f(60)` with `f(x) = if(x, f(x-1) + f(x-1), 1)` (2^60 calls at
/// depth 60) ran for ever.
pub const MAX_EVAL_CALLS: u64 = 1_000_000;

/// A linked expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    Num(f64),
    /// Input channel `$n` (1-based): a ray variable in patterns, a column in rcalc.
    Chan(usize),
    /// Real argument `n` of the pattern (1-based, 0 = their count): `A1`, `AC`.
    Arg(usize),
    /// A user definition used as a variable.
    Var(usize),
    /// Parameter `i` (0-based) of the function being evaluated.
    Param(usize),
    /// A library function's name used as a value (only meaningful as a function argument).
    LibName(Lib),
    Neg(Box<Expr>),
    Bin(Op, Box<Expr>, Box<Expr>),
    Call(Callee, Vec<Expr>),
    /// A name with no definition: an error when (and only when) it is evaluated, as in
    /// Radiance, which only complains when an undefined name is reached.
    Undefined {
        name: String,
        at: Location,
    },
}

/// What a call calls.
#[derive(Debug, Clone, PartialEq)]
pub enum Callee {
    User(usize),
    Lib(Lib),
    /// A function passed as parameter `i`.
    Param(usize),
    Undefined {
        name: String,
        at: Location,
    },
}

/// One linked definition.
#[derive(Debug, Clone, PartialEq)]
pub struct Def {
    pub name: String,
    /// `None` for variables, else the number of parameters.
    pub nparams: Option<usize>,
    pub body: Expr,
    pub at: Location,
}

/// What expressions read from the outside world.
#[derive(Debug, Clone, Copy, Default)]
pub struct Inputs<'a> {
    /// `$1`, `$2`, ...: ray variables (see [`super::RAY_VARIABLES`]) or input columns.
    pub chan: &'a [f64],
    /// The pattern's real arguments (`arg(n)`, `A1`...).
    pub args: &'a [f64],
}

impl Inputs<'_> {
    fn chan(&self, n: usize) -> f64 {
        n.checked_sub(1)
            .and_then(|k| self.chan.get(k))
            .copied()
            .unwrap_or(0.0)
    }
}

/// An activation record: the arguments of the function being evaluated, evaluated on
/// demand in the caller's frame and kept once computed.
pub(super) struct Frame<'a> {
    name: &'a str,
    args: Args<'a>,
    caller: Option<&'a Frame<'a>>,
    memo: [Cell<Option<f64>>; 8],
}

enum Args<'a> {
    Exprs(&'a [Expr]),
    Values(&'a [f64]),
}

impl<'a> Frame<'a> {
    pub(super) fn values(name: &'a str, v: &'a [f64]) -> Frame<'a> {
        Frame {
            name,
            args: Args::Values(v),
            caller: None,
            memo: Default::default(),
        }
    }
    fn len(&self) -> usize {
        match self.args {
            Args::Exprs(e) => e.len(),
            Args::Values(v) => v.len(),
        }
    }
}

pub(super) fn binop(op: Op, a: f64, b: f64) -> f64 {
    match op {
        Op::Add => a + b,
        Op::Sub => a - b,
        Op::Mul => a * b,
        Op::Div => {
            if b == 0.0 {
                0.0
            } else {
                a / b
            }
        }
        Op::Pow => a.powf(b),
    }
}

pub(super) struct Eval<'p> {
    pub defs: &'p [Def],
    pub inputs: Inputs<'p>,
    /// Definitions evaluated so far (bounded by [`MAX_EVAL_CALLS`]).
    pub calls: Cell<u64>,
}

impl<'p> Eval<'p> {
    pub(super) fn new(defs: &'p [Def], inputs: Inputs<'p>) -> Self {
        Eval {
            defs,
            inputs,
            calls: Cell::new(0),
        }
    }

    /// Count one evaluation of `def`; an error once there have been too many.
    fn count(&self, def: &Def) -> crate::Result<()> {
        let n = self.calls.get() + 1;
        self.calls.set(n);
        if n > MAX_EVAL_CALLS {
            return Err(Error::parse(
                def.at.clone(),
                format!(
                    "evaluating '{}' takes more than {MAX_EVAL_CALLS} evaluations of definitions (a function that calls itself more than once per level?)",
                    def.name
                ),
            ));
        }
        Ok(())
    }

    fn too_deep(&self, what: &str, at: &Location) -> Error {
        Error::parse(
            at.clone(),
            format!(
                "evaluating '{what}' nests deeper than {MAX_EVAL_DEPTH} levels (a definition that refers to itself without end?)"
            ),
        )
    }

    pub(super) fn eval(&self, e: &Expr, f: Option<&Frame<'_>>, depth: usize) -> crate::Result<f64> {
        if depth > MAX_EVAL_DEPTH {
            // Name the innermost function if any.
            let (name, at) = match f {
                Some(fr) => (fr.name, self.def_at(fr.name)),
                None => ("expression", Location::default()),
            };
            return Err(self.too_deep(name, &at));
        }
        Ok(match e {
            Expr::Num(v) => *v,
            Expr::Chan(n) => self.inputs.chan(*n),
            Expr::Arg(n) => {
                return Lib::Arg.call(1, &mut |_| Ok(*n as f64), &|_| 0.0, self.inputs.args);
            }
            Expr::Var(d) => {
                let def = &self.defs[*d];
                if def.nparams.is_some() {
                    return Err(Error::parse(
                        def.at.clone(),
                        format!("'{}' is a function, used as a variable", def.name),
                    ));
                }
                if depth >= MAX_EVAL_DEPTH {
                    return Err(self.too_deep(&def.name, &def.at));
                }
                self.count(def)?;
                self.eval(&def.body, None, depth + 1)?
            }
            Expr::Param(i) => return self.param(*i, f, depth),
            Expr::LibName(_) => {
                return Err(Error::Usage(
                    "a library function's name used as a value".to_string(),
                ));
            }
            Expr::Neg(a) => -self.eval(a, f, depth + 1)?,
            Expr::Bin(op, a, b) => {
                // Radiance evaluates the divisor first; order does not matter for values.
                let x = self.eval(a, f, depth + 1)?;
                let y = self.eval(b, f, depth + 1)?;
                binop(*op, x, y)
            }
            Expr::Call(callee, args) => return self.call_exprs(callee, args, f, depth + 1),
            Expr::Undefined { name, at } => {
                return Err(Error::parse(
                    at.clone(),
                    format!("undefined variable '{name}'"),
                ));
            }
        })
    }

    /// A call from an expression (kept out of [`Eval::eval`] so that its stack frame, which
    /// every nesting level pays, stays small).
    #[inline(never)]
    fn call_exprs(
        &self,
        callee: &Callee,
        args: &[Expr],
        f: Option<&Frame<'_>>,
        depth: usize,
    ) -> crate::Result<f64> {
        let callee = self.resolve(callee, f)?;
        let frame = Frame {
            name: "",
            args: Args::Exprs(args),
            caller: f,
            memo: Default::default(),
        };
        self.call(&callee, frame, depth)
    }

    fn def_at(&self, name: &str) -> Location {
        self.defs
            .iter()
            .rev()
            .find(|d| d.name == name)
            .map(|d| d.at.clone())
            .unwrap_or_default()
    }

    /// Parameter `i` of frame `f`.
    fn param(&self, i: usize, f: Option<&Frame<'_>>, depth: usize) -> crate::Result<f64> {
        let Some(fr) = f else {
            return Err(Error::Usage("function parameter outside a function".into()));
        };
        if let Some(v) = fr.memo.get(i).and_then(|c| c.get()) {
            return Ok(v);
        }
        let v = match fr.args {
            Args::Values(v) => v.get(i).copied(),
            Args::Exprs(e) => match e.get(i) {
                Some(a) => Some(self.eval(a, fr.caller, depth + 1)?),
                None => None,
            },
        };
        let Some(v) = v else {
            return Err(Error::parse(
                self.def_at(fr.name),
                format!(
                    "{}() has too few arguments: called with {}, needs argument {}",
                    fr.name,
                    fr.len(),
                    i + 1
                ),
            ));
        };
        if let Some(c) = fr.memo.get(i) {
            c.set(Some(v));
        }
        Ok(v)
    }

    /// A function passed as an argument: follow parameters back to a name.
    fn resolve(&self, c: &Callee, f: Option<&Frame<'_>>) -> crate::Result<Callee> {
        let mut c = c.clone();
        let mut f = f;
        while let Callee::Param(i) = c {
            let fr =
                f.ok_or_else(|| Error::Usage("function parameter outside a function".into()))?;
            let arg = match fr.args {
                Args::Exprs(e) => e.get(i),
                Args::Values(_) => None,
            };
            c = match arg {
                Some(Expr::Var(d)) => Callee::User(*d),
                Some(Expr::LibName(l)) => Callee::Lib(*l),
                Some(Expr::Param(j)) => Callee::Param(*j),
                Some(Expr::Undefined { name, at }) => Callee::Undefined {
                    name: name.clone(),
                    at: at.clone(),
                },
                _ => {
                    return Err(Error::parse(
                        self.def_at(fr.name),
                        format!("{}(): argument {} is not a function", fr.name, i + 1),
                    ));
                }
            };
            f = fr.caller;
        }
        Ok(c)
    }

    pub(super) fn call(
        &self,
        callee: &Callee,
        frame: Frame<'_>,
        depth: usize,
    ) -> crate::Result<f64> {
        match callee {
            Callee::User(d) => {
                let def = &self.defs[*d];
                if def.nparams.is_none() {
                    return match Lib::lookup(&def.name) {
                        Some(l) => self.call(&Callee::Lib(l), frame, depth),
                        None => Err(Error::parse(
                            def.at.clone(),
                            format!("'{}' is a variable, called as a function", def.name),
                        )),
                    };
                }
                let frame = Frame {
                    name: &def.name,
                    ..frame
                };
                if depth >= MAX_EVAL_DEPTH {
                    return Err(self.too_deep(&def.name, &def.at));
                }
                self.count(def)?;
                self.eval(&def.body, Some(&frame), depth + 1)
            }
            Callee::Lib(l) => {
                let n = frame.len();
                let fr = &frame;
                let mut arg = |k: usize| -> crate::Result<f64> {
                    if k >= n {
                        return Err(Error::Usage(format!(
                            "{}() has too few arguments: called with {n}, needs argument {}",
                            format!("{l:?}").to_lowercase(),
                            k + 1
                        )));
                    }
                    self.param(k, Some(fr), depth + 1)
                };
                let inputs = self.inputs;
                l.call(n, &mut arg, &|c| inputs.chan(c), self.inputs.args)
            }
            Callee::Param(_) => Err(Error::Usage("unresolved function parameter".into())),
            Callee::Undefined { name, at } => Err(Error::parse(
                at.clone(),
                format!("undefined function '{name}'"),
            )),
        }
    }
}
