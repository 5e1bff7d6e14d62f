//! Radiance's `.cal` expression language (`calcomp`: `src/common/calexpr.c`, `caldefn.c`,
//! `calfunc.c`; the `rcalc(1)` and `icalc(1)` manuals), as patterns, textures and
//! `rcalc` use it.
//!
//! - [`parse`]: the grammar, in `nom`, with `file:line:column` errors saying what was found
//!   and what was expected.
//! - [`eval`]: evaluation of the linked tree with `f64`, pure (no global state), so one
//!   [`Program`] serves every thread.
//! - [`library`]: built-in functions (Radiance's library, rtrace's ray variables, and the
//!   helpers of `rayinit.cal`).
//!
//! ```
//! use rdaylight_physics::calc::{Inputs, Program};
//! let p = Program::parse("sq3(x) = x*x*x;  half : .5;  arr(i) = select(i, 4, 5, 6);", "t.cal").unwrap();
//! let e = p.expr("sq3(2) + half + arr(0) + arr(2) - -2^2", "expr").unwrap();
//! assert_eq!(p.eval(&e, Inputs::default()).unwrap(), 8.0 + 0.5 + 3.0 + 5.0 - 4.0);
//! ```

pub mod eval;
pub mod library;
pub mod parse;
pub mod pattern;
pub mod xf;

use std::collections::HashMap;

pub use eval::{Expr, Inputs};
pub use library::RAY_VARIABLES;

use crate::error::{Error, Location, Result};
use eval::{Callee, Def, Eval, Frame};
use parse::{Raw, RawDef};

/// A set of definitions (one or more `.cal` files), linked and ready to evaluate.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Program {
    defs: Vec<Def>,
    /// Name -> index of its (last) definition.
    names: HashMap<String, usize>,
    /// Raw definitions with their sources, kept to relink when files are added.
    raw: Vec<(RawDef, usize)>,
    sources: Vec<(String, String)>,
}

impl Program {
    /// Parse and link one file's text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Program> {
        let mut p = Program::default();
        p.add(text, file)?;
        Ok(p)
    }

    /// Read and parse a `.cal` file from disk.
    pub fn load(path: &std::path::Path) -> Result<Program> {
        let shown = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| Error::io(&shown, e))?;
        Program::parse(&String::from_utf8_lossy(&bytes), &shown)
    }

    /// Add another file's definitions (later definitions replace earlier ones).
    pub fn add(&mut self, text: &str, file: &str) -> Result<()> {
        let raw = parse::parse_file(text, file)?;
        let k = self.sources.len();
        self.sources.push((file.to_string(), text.to_string()));
        self.raw.extend(raw.into_iter().map(|d| (d, k)));
        self.relink();
        Ok(())
    }

    fn loc(&self, src: usize, off: usize) -> Location {
        let (file, text) = match self.sources.get(src) {
            Some((f, t)) => (f.as_str(), t.as_str()),
            None => ("", ""),
        };
        let (l, c) = parse::line_col(text, off);
        Location::at(file, l, c)
    }

    fn relink(&mut self) {
        // Radiance keeps one definition per name: the last one read.
        let mut names: HashMap<String, usize> = HashMap::new();
        let mut order: Vec<usize> = Vec::new();
        for (k, (d, _)) in self.raw.iter().enumerate() {
            if let Some(old) = names.insert(d.name.clone(), k) {
                order.retain(|&o| o != old);
            }
            order.push(k);
        }
        let index: HashMap<String, usize> = order
            .iter()
            .enumerate()
            .map(|(i, &k)| (self.raw[k].0.name.clone(), i))
            .collect();
        let defs = order
            .iter()
            .map(|&k| {
                let (d, src) = &self.raw[k];
                let params = d.params.as_deref().unwrap_or(&[]);
                Def {
                    name: d.name.clone(),
                    nparams: d.params.as_ref().map(|p| p.len()),
                    body: self.link(&d.body, params, &index, *src),
                    at: self.loc(*src, d.at),
                }
            })
            .collect();
        self.defs = defs;
        self.names = index;
    }

    fn link(&self, r: &Raw, params: &[String], index: &HashMap<String, usize>, src: usize) -> Expr {
        self.link_with(r, params, index, &|off| self.loc(src, off))
    }

    /// Link `r`; `loc` gives the location of a byte offset in its source.
    fn link_with(
        &self,
        r: &Raw,
        params: &[String],
        index: &HashMap<String, usize>,
        loc: &dyn Fn(usize) -> Location,
    ) -> Expr {
        let param = |n: &str| params.iter().position(|p| p == n);
        match r {
            Raw::Num(v) => Expr::Num(*v),
            Raw::Chan(n) => Expr::Chan(*n),
            Raw::Neg(a) => Expr::Neg(Box::new(self.link_with(a, params, index, loc))),
            Raw::Bin(op, a, b) => Expr::Bin(
                *op,
                Box::new(self.link_with(a, params, index, loc)),
                Box::new(self.link_with(b, params, index, loc)),
            ),
            Raw::Name(n, at) => {
                if let Some(i) = param(n) {
                    return Expr::Param(i);
                }
                if let Some(&d) = index.get(n) {
                    return Expr::Var(d);
                }
                if let Some(&(_, c)) = RAY_VARIABLES.iter().find(|(v, _)| v == n) {
                    return Expr::Chan(c);
                }
                match library::variable(n) {
                    Some(Ok(v)) => return Expr::Num(v),
                    Some(Err(k)) => return Expr::Arg(k),
                    None => {}
                }
                if let Some(l) = library::Lib::lookup(n) {
                    return Expr::LibName(l);
                }
                Expr::Undefined {
                    name: n.clone(),
                    at: loc(*at),
                }
            }
            Raw::Call(n, at, args) => {
                let args = args
                    .iter()
                    .map(|a| self.link_with(a, params, index, loc))
                    .collect();
                let callee = if let Some(i) = param(n) {
                    Callee::Param(i)
                } else if let Some(&d) = index.get(n) {
                    Callee::User(d)
                } else if let Some(l) = library::Lib::lookup(n) {
                    Callee::Lib(l)
                } else {
                    Callee::Undefined {
                        name: n.clone(),
                        at: loc(*at),
                    }
                };
                Expr::Call(callee, args)
            }
        }
    }

    /// Parse an expression in the context of these definitions (a pattern's coordinate
    /// argument, an rcalc `-e` right-hand side); `name` labels it in errors.
    pub fn expr(&self, text: &str, name: &str) -> Result<Expr> {
        let raw = parse::parse_expr(text, name)?;
        let loc = |off: usize| {
            let (l, c) = parse::line_col(text, off);
            Location::at(name, l, c)
        };
        Ok(self.link_with(&raw, &[], &self.names, &loc))
    }

    /// Evaluate an expression from [`Program::expr`].
    pub fn eval(&self, e: &Expr, inputs: Inputs<'_>) -> Result<f64> {
        Eval::new(&self.defs, inputs).eval(e, None, 0)
    }

    /// Whether evaluating `e` can read the ray (`$n`, `Dx`..., `D(i)`...): a static check
    /// through every definition it can reach, so a constant result can be computed once.
    pub fn reads_ray(&self, e: &Expr) -> bool {
        let mut seen = vec![false; self.defs.len()];
        self.reads_ray_in(e, &mut seen)
    }

    /// [`Program::reads_ray`] for a function handle's body.
    pub fn function_reads_ray(&self, f: &Function) -> bool {
        let mut seen = vec![false; self.defs.len()];
        match &f.callee {
            Callee::User(d) => self.def_reads_ray(*d, &mut seen),
            Callee::Lib(l) => matches!(l, library::Lib::Vec3(_)),
            _ => false,
        }
    }

    fn def_reads_ray(&self, d: usize, seen: &mut [bool]) -> bool {
        match seen.get_mut(d) {
            Some(s) if !*s => *s = true,
            _ => return false,
        }
        self.reads_ray_in(&self.defs[d].body, seen)
    }

    fn reads_ray_in(&self, e: &Expr, seen: &mut [bool]) -> bool {
        match e {
            Expr::Chan(_) => true,
            Expr::Num(_) | Expr::Arg(_) | Expr::Param(_) | Expr::Undefined { .. } => false,
            Expr::LibName(l) => matches!(l, library::Lib::Vec3(_)),
            Expr::Var(d) => self.def_reads_ray(*d, seen),
            Expr::Neg(a) => self.reads_ray_in(a, seen),
            Expr::Bin(_, a, b) => self.reads_ray_in(a, seen) || self.reads_ray_in(b, seen),
            Expr::Call(c, args) => {
                let callee = match c {
                    Callee::User(d) => self.def_reads_ray(*d, seen),
                    Callee::Lib(l) => matches!(l, library::Lib::Vec3(_)),
                    // A function passed in: its name is among the caller's arguments,
                    // which are checked below.
                    Callee::Param(_) | Callee::Undefined { .. } => false,
                };
                callee || args.iter().any(|a| self.reads_ray_in(a, seen))
            }
        }
    }

    /// Whether `name` is defined in the files (not counting built-ins).
    pub fn defines(&self, name: &str) -> bool {
        self.names.contains_key(name)
    }

    /// The value of variable `name`.
    pub fn var(&self, name: &str, inputs: Inputs<'_>) -> Result<f64> {
        let e = self.expr(name, name)?;
        self.eval(&e, inputs)
    }

    /// A callable handle on function `name` (user-defined or built in), or an error naming
    /// it when it is defined nowhere.
    pub fn function(&self, name: &str) -> Result<Function> {
        let callee = if let Some(&d) = self.names.get(name) {
            Callee::User(d)
        } else if let Some(l) = library::Lib::lookup(name) {
            Callee::Lib(l)
        } else {
            return Err(Error::Usage(format!("undefined function '{name}'")));
        };
        Ok(Function {
            name: name.to_string(),
            callee,
        })
    }

    /// Call a function handle with argument values.
    pub fn call(&self, f: &Function, args: &[f64], inputs: Inputs<'_>) -> Result<f64> {
        Eval::new(&self.defs, inputs).call(&f.callee, Frame::values(&f.name, args), 0)
    }
}

/// A function of a [`Program`] resolved once (see [`Program::function`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Function {
    name: String,
    callee: Callee,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(defs: &str, e: &str) -> Result<f64> {
        let p = Program::parse(defs, "t.cal")?;
        let x = p.expr(e, "e")?;
        p.eval(&x, Inputs::default())
    }

    #[test]
    fn precedence_and_unary_minus() {
        assert_eq!(ev("", "-2^2").unwrap(), 4.0);
        assert_eq!(ev("", "2^3^2").unwrap(), 512.0);
        assert_eq!(ev("", "2--3").unwrap(), 5.0);
        assert_eq!(ev("", "1+2*3-4/2").unwrap(), 5.0);
        assert_eq!(ev("x = 0;", "1/x").unwrap(), 0.0);
    }

    #[test]
    fn later_definitions_win_and_order_does_not_matter() {
        assert_eq!(ev("a = b + 1; b = 2; a = b * 10;", "a").unwrap(), 20.0);
    }

    #[test]
    fn functions_as_arguments() {
        let d = "v(i) = select(i, 1, 2, 3); w(i) = select(i, 4, 5, 6); \
                 dot(a, b) = a(1)*b(1) + a(2)*b(2) + a(3)*b(3); f(g, x) = g(x);";
        assert_eq!(ev(d, "dot(v, w)").unwrap(), 32.0);
        assert_eq!(ev(d, "f(sqrt, 16)").unwrap(), 4.0);
    }

    #[test]
    fn recursion_terminates_through_if_and_runaway_is_an_error() {
        assert_eq!(
            ev("fact(n) = if(n - .5, n*fact(n-1), 1);", "fact(10)").unwrap(),
            3628800.0
        );
        let e = ev("x = x + 1;", "x").unwrap_err().to_string();
        assert!(
            e.starts_with("t.cal:1:1: evaluating 'x' nests deeper"),
            "{e}"
        );
    }

    #[test]
    fn undefined_names_name_themselves_where_used() {
        let e = ev("f(x) = g(x) * 2;", "f(3)").unwrap_err().to_string();
        assert_eq!(e, "t.cal:1:8: undefined function 'g'");
        let e = ev("\n y = 2 * zz;", "y").unwrap_err().to_string();
        assert_eq!(e, "t.cal:2:10: undefined variable 'zz'");
        // Unused undefined names are fine (Radiance only complains on use).
        assert_eq!(ev("f(x) = noise3(x, x, x); y = 1;", "y").unwrap(), 1.0);
    }

    #[test]
    fn syntax_errors_say_where_and_what() {
        let e = Program::parse("a = 1;\nb = (2 + ;", "s.cal")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "s.cal:2:10: expected a number, a name, '$N', '-' or '(', found ';'"
        );
        let e = Program::parse("a = 1 b = 2;", "s.cal")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "s.cal:1:7: expected ';' or an operator, found 'b'");
        let e = Program::parse("a = 1/0;", "s.cal").unwrap_err().to_string();
        assert_eq!(
            e,
            "s.cal:1:7: expected a divisor other than the constant 0, found '0'"
        );
        let e = Program::parse("{ open comment\n a = 1;", "s.cal")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "s.cal:1:1: expected '}' closing this comment, found '{'");
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_crash() {
        let deep = format!("a = {}1{};", "(".repeat(5000), ")".repeat(5000));
        let e = Program::parse(&deep, "d.cal").unwrap_err().to_string();
        assert!(e.contains("at most 100 levels of nesting"), "{e}");
        let ok = format!("a = {}1{};", "(".repeat(90), ")".repeat(90));
        assert_eq!(ev(&ok, "a").unwrap(), 1.0);
        let minus = format!("a = {}1;", "-(".repeat(5000));
        assert!(Program::parse(&minus, "d.cal").is_err());
    }

    /// Fuzzing (fuzz/README.md, `cal` target): recursion that branches stays shallow while
    /// its calls double per level, so the depth bound never fired and `f(60)` ran for ever.
    #[test]
    fn branching_recursion_is_an_error_not_a_hang() {
        let p = Program::parse("f(x) = if(x, f(x-1)+f(x-1), 1);", "x.cal").unwrap();
        let e = p.expr("f(60)", "e").unwrap();
        let err = p.eval(&e, Inputs::default()).unwrap_err().to_string();
        assert_eq!(
            err,
            "x.cal:1:1: evaluating 'f' takes more than 1000000 evaluations of definitions (a \
             function that calls itself more than once per level?)"
        );
        // 2^16 calls are fine, and each evaluation starts a fresh count.
        let e = p.expr("f(16)", "e").unwrap();
        for _ in 0..3 {
            assert_eq!(p.eval(&e, Inputs::default()).unwrap(), 65536.0);
        }
        let f = p.function("f").unwrap();
        assert!(p.call(&f, &[60.0], Inputs::default()).is_err());
    }

    #[test]
    fn truncated_prefixes_never_panic() {
        let text = "{ sky } f(x, y) : x^2 + -y*(3.5e-1 - $2);\narr(i) = select(i, A1, 2.);\n\
                    g = if(Dz, f(arr(1), Dx) / 2, PI) ; ";
        for end in 0..=text.len() {
            if let Ok(p) = Program::parse(&text[..end], "p.cal") {
                if p.defines("g") {
                    let _ = p.var("g", Inputs::default());
                }
            }
        }
        assert!(Program::parse(text, "p.cal").is_ok());
    }

    #[test]
    fn reads_ray_follows_definitions_and_function_arguments() {
        let p = Program::parse(
            "a = b + 1; b = Dz; c = arg(1) * 2; f(x) = x * PI; g(h, x) = h(x); \
             r(i) = rand(i); up(i) = N(i);",
            "r.cal",
        )
        .unwrap();
        let reads = |e: &str| p.reads_ray(&p.expr(e, "e").unwrap());
        assert!(reads("a"));
        assert!(!reads("c + f(3) + r(2)"));
        assert!(reads("f(Px)"));
        assert!(reads("g(up, 3)"));
        assert!(!reads("g(r, 3)"));
        assert!(reads("$3"));
        assert!(p.function_reads_ray(&p.function("up").unwrap()));
        assert!(!p.function_reads_ray(&p.function("f").unwrap()));
    }

    #[test]
    fn ray_variables_and_arguments() {
        let p = Program::parse("v = Dz * 10 + A2 + arg(0);", "r.cal").unwrap();
        let mut chan = [0.0; 27];
        chan[2] = 0.5;
        let args = [7.0, 3.0];
        let x = p
            .var(
                "v",
                Inputs {
                    chan: &chan,
                    args: &args,
                },
            )
            .unwrap();
        assert_eq!(x, 5.0 + 3.0 + 2.0);
        let e = p
            .var(
                "v",
                Inputs {
                    chan: &chan,
                    args: &[1.0],
                },
            )
            .unwrap_err();
        assert!(e.to_string().contains("missing real argument 2"), "{e}");
    }
}
