//! The `.cal` evaluator ([`rdaylight::cal`]) against real Radiance's `rcalc`.
//!
//! One table of expressions (precedence, unary minus, right-associative `^`, every library
//! function, user functions, recursion, functions passed as arguments, arrays through
//! `select`, `if`, the `rayinit.cal` helpers) is evaluated by us and by `rcalc -f
//! rayinit.cal`. To compare to 1e-12 relative although rcalc prints 8 digits, rcalc is
//! handed our value with 17 digits and prints the difference `(expr) - ours`, which must
//! be within 1e-12 of |ours| (0 for most rows).

use crate::common;

use rdaylight::calc::{Inputs, Program};

/// Definitions shared by the table (a small `.cal` file).
const DEFS: &str = "
{ user functions, arrays, recursion, functions as arguments }
sq3(x) = x*x*x;
half : .5;
arr(i) = select(i, 4, -5.5, 6e-1);
fact(n) = if(n - .5, n * fact(n - 1), 1);
poly(a, b, c, x) = (a*x + b)*x + c;
apply(g, x) = g(x) + 1;
twice(g, x) = apply(g, g(x));
v1(i) = select(i, 1, 2, 3);
v2(i) = select(i, -4, 5.5, 6);
mydot(a, b) = a(1)*b(1) + a(2)*b(2) + a(3)*b(3);
late = early * 2;
early = 21;
zero = 0;
nested(x) = sq3(poly(1, -2, .25, x)) / (1 + x^2);
";

const EXPRS: &[&str] = &[
    "1+2*3-4/2",
    "-2^2",
    "2^3^2",
    "2^-1",
    "-2^-2",
    "2--3",
    "+3*-2",
    "(1+2)*(3-4)/5",
    "1/3*3",
    "7/zero",
    "10 - 4 - 3",
    "64 / 4 / 2",
    "1.5e3 + .25 + 5. + 2E-2",
    "-(-(3))",
    "sin(.7) + cos(.7) + tan(.7)",
    "asin(.3) + acos(.3) + atan(3)",
    "atan2(1, -1) + atan2(-1, -1)",
    "exp(1.5) + log(7) + log10(1000)",
    "sqrt(2)",
    "floor(-1.5) + ceil(-1.5) + floor(2.7) + ceil(2.2)",
    "min(3, -1, 2) + max(3, 9, 2) + min(4) + max(-4)",
    "rand(.3) + rand(-17.25) + rand(1e6)",
    "if(0, 1, 2) + if(-1, 10, 20) + if(1e-300, 100, 200)",
    "select(0, 4, 5, 6) + select(3, 4, 5, 6) + select(1.4, 7, 8)",
    "select(5, 1, 2) + select(-1, 2)",
    "sq3(1.1) + half",
    "arr(0) + arr(1) + arr(2) + arr(3)",
    "fact(10)",
    "poly(1, -2, 3, 1.5)",
    "apply(sqrt, 16) + twice(sq3, 1.2)",
    "mydot(v1, v2)",
    "late",
    "nested(.3) + nested(-2.5)",
    "PI + DEGREE",
    "abs(-3) + sgn(-2) + sgn(0) + sgn(5) + sq(1.5)",
    "bound(0, 1.5, 1) + bound(0, -1, 1) + bound(0, .25, 1) + clip(2) + noneg(-3)",
    "Acos(1.2) + Asin(-1.5) + Sqrt(-1) + Exp(-200) + Atan2(0, 0) + Atan2(1, 1)",
    "and(1, 2) + and(-1, 2) + or(-1, 2) + or(3, 4) + not(1) + not(-1) + xor(1, 1) + xor(-1, 1)",
    "inside(0, .5, 1) + inside(0, 2, 1) + frac(-1.25) + mod(7.5, 2) + mod(-7.5, 2)",
    "tri(2.5, 1) + linterp(.25, 10, 20) + noop(3)",
];

fn ours(p: &Program, e: &str) -> f64 {
    let x = p.expr(e, "expr").unwrap_or_else(|err| panic!("{e}: {err}"));
    p.eval(&x, Inputs::default())
        .unwrap_or_else(|err| panic!("{e}: {err}"))
}

#[test]
fn expressions_agree_with_rcalc() {
    let p = Program::parse(DEFS, "defs.cal").unwrap();
    let values: Vec<f64> = EXPRS.iter().map(|e| ours(&p, e)).collect();
    if !common::have_radiance("expressions_agree_with_rcalc") {
        return;
    }
    let mut cmd = common::radiance("rcalc");
    cmd.args(["-n", "-f", "rayinit.cal", "-e", DEFS]);
    for (k, (e, v)) in EXPRS.iter().zip(&values).enumerate() {
        assert!(v.is_finite(), "{e} = {v}");
        cmd.arg("-e")
            .arg(format!("${} = ({e}) - ({v:.17e});", k + 1));
    }
    let out = common::run_ok(&mut cmd, b"");
    let text = String::from_utf8(out).unwrap();
    let diffs: Vec<f64> = text
        .split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect();
    assert_eq!(diffs.len(), EXPRS.len(), "rcalc printed: {text}");
    for ((e, v), d) in EXPRS.iter().zip(&values).zip(&diffs) {
        assert!(
            d.abs() <= 1e-12 * v.abs().max(1e-300),
            "{e}: ours {v}, rcalc differs by {d}"
        );
    }
}

#[test]
fn non_finite_results_pass_through_like_rcalc() {
    // rcalc (Radiance 6) prints inf / -inf / nan for these; division by zero is 0 (a
    // division by the *constant* 0 is refused when parsing, as rtrace does under E_RCONST;
    // rcalc, which does not set E_RCONST, evaluates it to 0).
    let p = Program::parse("zero = 0;", "x.cal").unwrap();
    let v = |e: &str| ours(&p, e);
    assert_eq!(v("exp(1000)"), f64::INFINITY);
    assert_eq!(v("log(0)"), f64::NEG_INFINITY);
    assert_eq!(v("0^-1"), f64::INFINITY);
    assert!(v("sqrt(-1)").is_nan());
    assert!(v("acos(2)").is_nan());
    assert_eq!(v("1/zero"), 0.0);
    if !common::have_radiance("non_finite_results_pass_through_like_rcalc") {
        return;
    }
    let out = common::run_ok(
        common::radiance("rcalc").args([
            "-n",
            "-e",
            "$1=exp(1000);$2=log(0);$3=0^-1;$4=sqrt(-1);$5=acos(2);zero=0;$6=1/zero",
        ]),
        b"",
    );
    let text = String::from_utf8_lossy(&out);
    let w: Vec<&str> = text.split_whitespace().collect();
    assert_eq!(w.len(), 6, "{text}");
    assert_eq!(w[0], "inf");
    assert_eq!(w[1], "-inf");
    assert_eq!(w[2], "inf");
    assert!(w[3].contains("nan"));
    assert!(w[4].contains("nan"));
    assert_eq!(w[5].parse::<f64>().unwrap(), 0.0);
}

#[test]
fn undefined_function_names_itself_in_both() {
    let p = Program::parse("f(x) = g(x) * 2;", "u.cal").unwrap();
    let e = p.expr("f(3)", "expr").unwrap();
    let err = p.eval(&e, Inputs::default()).unwrap_err().to_string();
    assert_eq!(err, "u.cal:1:8: undefined function 'g'");
    if !common::have_radiance("undefined_function_names_itself_in_both") {
        return;
    }
    let out = common::run(
        common::radiance("rcalc").args(["-n", "-e", "f(x)=g(x)*2;$1=f(3)"]),
        b"",
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("g(): undefined function"));
}

/// A small deterministic generator (xorshift64*) for the robustness tests.
struct Gen(u64);
impl Gen {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn pick<'a>(&mut self, from: &[&'a str]) -> &'a str {
        from[(self.next() % from.len() as u64) as usize]
    }
}

#[test]
fn random_cal_text_never_panics() {
    // Tokens of the language, glued at random (plus raw random bytes), parsed and, when
    // that succeeds, every definition evaluated: errors are fine, panics and stack
    // overflows are not.
    let tokens = [
        "a", "b", "f", "x", "(", ")", ",", ";", "=", ":", "+", "-", "*", "/", "^", "1", ".5",
        "2e3", "$1", "if", "select", "sqrt", "Dz", "A1", "{c}", " ", "\n", "PI", "`",
    ];
    let mut g = Gen(0x9e37_79b9_7f4a_7c15);
    let mut parsed = 0;
    for _ in 0..3000 {
        // Mostly "name = <random tokens>" so that a fair share parses and evaluates.
        let n = 1 + (g.next() % 12) as usize;
        let body: String = (0..n).map(|_| g.pick(&tokens)).collect();
        let text = match g.next() % 4 {
            0 => body,
            _ => format!("{} = {body}", g.pick(&["a", "b", "x", "f(x)", "f(a, b)"])),
        };
        if let Ok(p) = Program::parse(&text, "r.cal") {
            parsed += 1;
            for name in ["a", "b", "x"] {
                if p.defines(name) {
                    let _ = p.var(name, Inputs::default());
                }
            }
            if let Ok(f) = p.function("f") {
                let _ = p.call(&f, &[1.0, 2.0], Inputs::default());
            }
        }
    }
    assert!(parsed > 200, "only {parsed} random programs parsed");
    for _ in 0..500 {
        let bytes: Vec<u8> = (0..(g.next() % 64)).map(|_| g.next() as u8).collect();
        let _ = Program::parse(&String::from_utf8_lossy(&bytes), "r.cal");
    }
}

#[test]
fn random_data_files_never_panic() {
    use rdaylight::scene::specdata::DataArray;
    let tokens = [
        "0", "1", "2", "3", "-1", "0.5", "380", "780", "1e9", "x", "#c\n", " ", "\n",
    ];
    let mut g = Gen(0x1234_5678_9abc_def1);
    for _ in 0..3000 {
        let n = (g.next() % 30) as usize;
        let text: String = (0..n).map(|_| g.pick(&tokens)).collect();
        if let Ok(d) = DataArray::parse(&text, "r.dat") {
            let pt = [0.3, 700.0, -5.0, 1e3, 2.0];
            let _ = d.value(&pt[..d.dims()]);
            if d.dims() >= 2 {
                let _ = d.vector(&pt[..d.dims() - 1]);
            }
        }
    }
}
