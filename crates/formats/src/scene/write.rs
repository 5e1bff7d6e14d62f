//! Writing scenes in Radiance's canonical layout.
//!
//! ```text
//! modifier type identifier
//! N s1 ... sN
//! 0
//! M r1 ... rM
//! ```
//!
//! Reals are written in Rust's shortest round-trip form (`{}`; `{:e}` for very large or
//! small magnitudes, which Radiance's `isflt` also accepts), so parse -> write -> parse
//! reproduces every `f64` bit for bit. Words that need it are quoted the way `fgetword`
//! unquotes them (quoted segments may be concatenated, so any text survives).
//! Aliases are written back as `modifier alias id old_id`.

use std::fmt;
use std::io;

use super::{Object, Primitive, Scene};

/// A real in a form that Radiance reads back to the same `f64`.
pub fn format_real(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A word quoted only if needed: white space, quotes or emptiness.
pub fn quote_word(w: &str) -> String {
    let plain = !w.is_empty()
        && !w
            .chars()
            .any(|c| c.is_ascii_whitespace() || c == '\x0B' || c == '\'' || c == '"');
    if plain {
        return w.to_string();
    }
    if !w.contains('\'') {
        return format!("'{w}'");
    }
    if !w.contains('"') {
        return format!("\"{w}\"");
    }
    // Both kinds of quote: single-quote everything but single quotes, which go in "...".
    let mut out = String::new();
    for (i, part) in w.split('\'').enumerate() {
        if i > 0 {
            out.push_str("\"'\"");
        }
        if !part.is_empty() {
            out.push('\'');
            out.push_str(part);
            out.push('\'');
        }
    }
    out
}

impl fmt::Display for Object {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = quote_word(&self.modifier_name);
        let id = quote_word(&self.id);
        if let Some(alias) = &self.alias {
            return writeln!(f, "{m} alias {id} {}", quote_word(&alias.target_id));
        }
        writeln!(f, "{m} {} {id}", self.type_name())?;
        let (strings, reals) = self.kind.to_args();
        write!(f, "{}", strings.len())?;
        for s in &strings {
            write!(f, " {}", quote_word(s))?;
        }
        writeln!(f)?;
        writeln!(f, "0")?;
        write!(f, "{}", reals.len())?;
        // Polygons one vertex per line; other long lists in rows of 5, short ones inline.
        let row = match self.kind {
            Primitive::Polygon { .. } => Some(3),
            _ if reals.len() > 9 => Some(5),
            _ => None,
        };
        match row {
            None => {
                for r in &reals {
                    write!(f, " {}", format_real(*r))?;
                }
                writeln!(f)
            }
            Some(n) => {
                writeln!(f)?;
                for chunk in reals.chunks(n) {
                    let words: Vec<String> = chunk.iter().map(|r| format_real(*r)).collect();
                    writeln!(f, "\t{}", words.join(" "))?;
                }
                Ok(())
            }
        }
    }
}

impl fmt::Display for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // `#@rfluxmtx` lines go back before the object they preceded (trailing ones last).
        let mut d = self.directives.iter().peekable();
        for (i, o) in self.objects.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            while let Some(x) = d.next_if(|x| x.before <= i) {
                writeln!(f, "{} {}", super::RFLUXMTX_DIRECTIVE, x.text)?;
            }
            write!(f, "{o}")?;
        }
        for x in d {
            write!(f, "\n{} {}", super::RFLUXMTX_DIRECTIVE, x.text)?;
        }
        Ok(())
    }
}

impl Scene {
    /// Write the scene as `.rad` text.
    pub fn write_rad<W: io::Write>(&self, mut w: W) -> io::Result<()> {
        write!(w, "{self}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_round_trip_bit_for_bit() {
        for v in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1.0 / 3.0,
            6.879e6,
            1e-7,
            -2.5e-300,
            1.7976931348623157e308,
            5e-324,
            123456789012345680.0,
        ] {
            let s = format_real(v);
            let back = crate::scene::parse::parse_real(&s).expect(&s);
            assert_eq!(back.to_bits(), v.to_bits(), "{v} -> {s}");
        }
    }

    #[test]
    fn words_are_quoted_only_when_needed() {
        assert_eq!(quote_word("skybright.cal"), "skybright.cal");
        assert_eq!(quote_word("1-Acos(Dz)/PI"), "1-Acos(Dz)/PI");
        assert_eq!(quote_word("a b"), "'a b'");
        assert_eq!(quote_word(""), "''");
        assert_eq!(quote_word("it's"), "\"it's\"");
        assert_eq!(quote_word("a'b\"c"), "'a'\"'\"'b\"c'");
    }
}
