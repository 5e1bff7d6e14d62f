//! The functions and variables a `.cal` file may use without defining them.
//!
//! - Library functions of `src/common/calfunc.c`: `if select min max rand floor ceil sqrt
//!   sin cos tan asin acos atan atan2 exp log log10`. Arguments are evaluated lazily (only
//!   the branch `if` takes). `select(0, ...)` is the number of items, an index outside the
//!   list is a domain error that gives 0; `if(c, a, b)` takes `a` when `c > 0`. The installed
//!   Radiance 6 passes NaN and infinity through (`sqrt(-1)` prints `-nan`, `exp(1000)`
//!   `inf` with rcalc), and so do we.
//! - What `rtrace` adds (`src/rt/func.c: initfunc`): the ray channels `Dx`..`Lv` (see
//!   [`RAY_VARIABLES`]), `arg(n)` (real argument `n`, `arg(0)` their count), `erf`, `erfc`.
//! - What Radiance's `rayinit.cal` defines, implemented natively here (it is not read):
//!   `PI DEGREE FTINY AC A1..A10`, `D(i) N(i) P(i)`, `bound Acos Asin Atan2 Exp Sqrt`,
//!   `and or not xor abs sgn sq inside frac mod tri linterp noop clip noneg`. Noise
//!   functions (`noise3`, `fnoise3`, `turbulence`...) are not provided: a file that calls
//!   them fails with "undefined function" at the call.
//!
//! A file's own definition of any of these names takes precedence, as in Radiance.

use rdaylight_base::stats::{erf, erfc};

/// Ray channels `$1..$27` as `initfunc` names them.
pub const RAY_VARIABLES: [(&str, usize); 27] = [
    ("Dx", 1),
    ("Dy", 2),
    ("Dz", 3),
    ("Nx", 4),
    ("Ny", 5),
    ("Nz", 6),
    ("Px", 7),
    ("Py", 8),
    ("Pz", 9),
    ("T", 10),
    ("Rdot", 11),
    ("S", 12),
    ("Tx", 13),
    ("Ty", 14),
    ("Tz", 15),
    ("Ix", 16),
    ("Iy", 17),
    ("Iz", 18),
    ("Jx", 19),
    ("Jy", 20),
    ("Jz", 21),
    ("Kx", 22),
    ("Ky", 23),
    ("Kz", 24),
    ("Ts", 25),
    ("Lu", 26),
    ("Lv", 27),
];

/// A built-in function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lib {
    If,
    Select,
    Min,
    Max,
    Rand,
    Floor,
    Ceil,
    Sqrt,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Exp,
    Log,
    Log10,
    Arg,
    Erf,
    Erfc,
    // rayinit.cal's helpers.
    Bound,
    AcosSafe,
    AsinSafe,
    Atan2Safe,
    ExpSafe,
    SqrtSafe,
    And,
    Or,
    Not,
    Xor,
    Abs,
    Sgn,
    Sq,
    Inside,
    Frac,
    Mod,
    Tri,
    Linterp,
    Noop,
    Clip,
    Noneg,
    /// `D(i)`, `N(i)`, `P(i)`: channel `base + i - 1` for i in 1..=3.
    Vec3(usize),
}

impl Lib {
    pub fn lookup(name: &str) -> Option<Lib> {
        use Lib::*;
        Some(match name {
            "if" => If,
            "select" => Select,
            "min" => Min,
            "max" => Max,
            "rand" => Rand,
            "floor" => Floor,
            "ceil" => Ceil,
            "sqrt" => Sqrt,
            "sin" => Sin,
            "cos" => Cos,
            "tan" => Tan,
            "asin" => Asin,
            "acos" => Acos,
            "atan" => Atan,
            "atan2" => Atan2,
            "exp" => Exp,
            "log" => Log,
            "log10" => Log10,
            "arg" => Arg,
            "erf" => Erf,
            "erfc" => Erfc,
            "bound" => Bound,
            "Acos" => AcosSafe,
            "Asin" => AsinSafe,
            "Atan2" => Atan2Safe,
            "Exp" => ExpSafe,
            "Sqrt" => SqrtSafe,
            "and" => And,
            "or" => Or,
            "not" => Not,
            "xor" => Xor,
            "abs" => Abs,
            "sgn" => Sgn,
            "sq" => Sq,
            "inside" => Inside,
            "frac" => Frac,
            "mod" => Mod,
            "tri" => Tri,
            "linterp" => Linterp,
            "noop" => Noop,
            "clip" => Clip,
            "noneg" => Noneg,
            "D" => Vec3(1),
            "N" => Vec3(4),
            "P" => Vec3(7),
            _ => return None,
        })
    }

    /// Evaluate with `n` arguments available through `a(k)` (0-based, lazy).
    pub fn call(
        self,
        n: usize,
        a: &mut dyn FnMut(usize) -> crate::Result<f64>,
        chan: &dyn Fn(usize) -> f64,
        args: &[f64],
    ) -> crate::Result<f64> {
        use Lib::*;
        let pos = |x: f64| x > 0.0;
        Ok(match self {
            If => {
                if pos(a(0)?) {
                    a(1)?
                } else {
                    a(2)?
                }
            }
            Select => {
                let a1 = a(0)?;
                let k = (a1 + 0.5) as i64; // C's (int)(a1 + .5)
                if a1 < -0.5 || k >= n as i64 {
                    0.0 // domain error
                } else if k == 0 {
                    (n - 1) as f64
                } else {
                    a(k as usize)?
                }
            }
            Max => {
                let mut m = a(0)?;
                for k in (1..n).rev() {
                    let v = a(k)?;
                    if m < v {
                        m = v;
                    }
                }
                m
            }
            Min => {
                let mut m = a(0)?;
                for k in (1..n).rev() {
                    let v = a(k)?;
                    if m > v {
                        m = v;
                    }
                }
                m
            }
            Rand => rand(a(0)?),
            Floor => a(0)?.floor(),
            Ceil => a(0)?.ceil(),
            Sqrt => a(0)?.sqrt(),
            Sin => a(0)?.sin(),
            Cos => a(0)?.cos(),
            Tan => a(0)?.tan(),
            Asin => a(0)?.asin(),
            Acos => a(0)?.acos(),
            Atan => a(0)?.atan(),
            Atan2 => a(0)?.atan2(a(1)?),
            Exp => a(0)?.exp(),
            Log => a(0)?.ln(),
            Log10 => a(0)?.log10(),
            Arg => {
                let k = (a(0)? + 0.5).floor();
                if k < 1.0 {
                    args.len() as f64
                } else {
                    match args.get(k as usize - 1) {
                        Some(v) => *v,
                        None => {
                            return Err(crate::Error::Usage(format!(
                                "missing real argument {k} (the pattern has {})",
                                args.len()
                            )));
                        }
                    }
                }
            }
            Erf => erf(a(0)?),
            Erfc => erfc(a(0)?),
            Bound => bound(a(0)?, a(1)?, a(2)?),
            AcosSafe => bound(-1.0, a(0)?, 1.0).acos(),
            AsinSafe => bound(-1.0, a(0)?, 1.0).asin(),
            Atan2Safe => {
                let (y, x) = (a(0)?, a(1)?);
                if pos(x * x + y * y) { y.atan2(x) } else { 0.0 }
            }
            ExpSafe => {
                let x = a(0)?;
                if pos(-x - 100.0) { 0.0 } else { x.exp() }
            }
            SqrtSafe => {
                let x = a(0)?;
                if pos(x) { x.sqrt() } else { 0.0 }
            }
            And => {
                let x = a(0)?;
                if pos(x) { a(1)? } else { x }
            }
            Or => {
                let x = a(0)?;
                if pos(x) { x } else { a(1)? }
            }
            Not => not(a(0)?),
            Xor => {
                let x = a(0)?;
                let y = a(1)?;
                if pos(x) { not(y) } else { y }
            }
            Abs => abs(a(0)?),
            Sgn => {
                let x = a(0)?;
                if pos(x) {
                    1.0
                } else if pos(-x) {
                    -1.0
                } else {
                    0.0
                }
            }
            Sq => {
                let x = a(0)?;
                x * x
            }
            Inside => {
                let (lo, x) = (a(0)?, a(1)?);
                if pos(x - lo) { a(2)? - x } else { x - lo }
            }
            Frac => {
                let x = a(0)?;
                x - x.floor()
            }
            Mod => modulo(a(0)?, a(1)?),
            Tri => {
                let (x, d) = (a(0)?, a(1)?);
                abs(d - modulo(x - d, 2.0 * d))
            }
            Linterp => {
                let t = a(0)?;
                (1.0 - t) * a(1)? + t * a(2)?
            }
            Noop => a(0)?,
            Clip => bound(0.0, a(0)?, 1.0),
            Noneg => {
                let x = a(0)?;
                if pos(x) { x } else { 0.0 }
            }
            Vec3(base) => {
                // select(i, x, y, z)
                let i = a(0)?;
                let k = (i + 0.5) as i64;
                if i < -0.5 || k > 3 {
                    0.0
                } else if k == 0 {
                    3.0
                } else {
                    chan(base + k as usize - 1)
                }
            }
        })
    }
}

/// Named constants (rayinit.cal's `PI`, `DEGREE`, `FTINY`) and `AC`, `A1..A10` as
/// `arg(n)`: `Some(Ok(value))` for constants, `Some(Err(n))` for arguments.
pub fn variable(name: &str) -> Option<Result<f64, usize>> {
    Some(match name {
        "PI" => Ok(std::f64::consts::PI),
        "DEGREE" => Ok(std::f64::consts::PI / 180.0),
        "FTINY" => Ok(1e-7),
        "AC" => Err(0),
        _ => {
            let k: usize = name.strip_prefix('A')?.parse().ok()?;
            if (1..=10).contains(&k) && name == format!("A{k}") {
                Err(k)
            } else {
                return None;
            }
        }
    })
}

fn bound(lo: f64, x: f64, hi: f64) -> f64 {
    if lo - x > 0.0 {
        lo
    } else if x - hi > 0.0 {
        hi
    } else {
        x
    }
}

fn not(x: f64) -> f64 {
    if x > 0.0 { -1.0 } else { 1.0 }
}

fn abs(x: f64) -> f64 {
    if x > 0.0 { x } else { -x }
}

fn modulo(n: f64, d: f64) -> f64 {
    n - (n / d).floor() * d
}

/// Radiance's deterministic `rand(x)` (calfunc.c `l_rand`): a hash of `x` in [0, 1).
/// The constants are e and pi/4 to 15 digits *as calfunc.c writes them*: the final
/// `1e5 / x` amplifies any difference in the last digits.
#[allow(clippy::approx_constant)]
fn rand(x: f64) -> f64 {
    let mut x = x * (1.0 / (1.0 + x * x) + 2.718_281_828_459_04);
    x += 0.785_398_163_397_447 - x.floor();
    x = 1e5 / x;
    x - x.floor()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_matches_known_values() {
        // Values from Abramowitz & Stegun table 7.1 / high-precision references.
        for (x, v) in [
            (0.5, 0.520_499_877_813_046_5),
            (1.0, 0.842_700_792_949_714_9),
            (2.0, 0.995_322_265_018_952_7),
            (3.0, 0.999_977_909_503_001_4),
        ] {
            assert!((erf(x) - v).abs() < 1e-14, "erf({x}) = {}", erf(x));
            assert!((erf(-x) + v).abs() < 1e-14);
        }
        assert!((erfc(3.0) - 2.209_049_699_858_544e-5).abs() < 1e-18);
        assert!((erfc(5.0) - 1.537_459_794_428_035e-12).abs() < 1e-24);
    }
}
