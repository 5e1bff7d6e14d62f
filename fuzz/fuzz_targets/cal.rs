//! Any text fed to the `.cal` parser (definitions, functions, arrays, constants, comments)
//! gives a program or Err, never a panic or a stack overflow; a program that parses links,
//! and evaluating what it defines gives a number or Err (deep self-reference is stopped).
//! The input is definitions, then optionally a line `---` and one expression.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::calc::{Inputs, Program};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (defs, expr) = text.split_once("\n---\n").unwrap_or((text, ""));
    let Ok(p) = Program::parse(defs, "fuzz.cal") else {
        return;
    };
    if !expr.is_empty()
        && let Ok(e) = p.expr(expr, "fuzz-expr")
    {
        let _ = p.reads_ray(&e);
        let _ = p.eval(&e, Inputs::default());
    }
    // Names Radiance's patterns and rcalc look up most.
    for name in ["A1", "red", "x", "y", "f"] {
        if p.defines(name) {
            let _ = p.var(name, Inputs::default());
        }
        if let Ok(f) = p.function(name) {
            let _ = p.function_reads_ray(&f);
            let _ = p.call(&f, &[0.5, 1.0], Inputs::default());
        }
    }
});
