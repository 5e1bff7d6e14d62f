//! # A small XML reader (the subset BSDF files use)
//!
//! LBNL WINDOW and Radiance's `wrapBSDF`/`bsdf2ttree` write plain XML 1.0: an optional
//! `<?xml ...?>` declaration, comments, elements with quoted attributes, character data with
//! the five predefined entities and numeric character references, and (rarely) CDATA
//! sections. Radiance reads them with `ezxml`; this reader accepts the same subset and
//! refuses document type declarations (`<!DOCTYPE`, which could define entities).
//!
//! The tokens are `nom` parsers; the tree is built with an explicit stack (no recursion), so
//! nesting depth, element count and file size are all bounded ([`MAX_DEPTH`],
//! [`MAX_ELEMENTS`]). Element and attribute names keep any namespace prefix; [`Element::local`]
//! drops it for matching, as `ezxml` ignores namespaces. Every element remembers the byte
//! offset where it starts so that later checks can name the file's line.

use nom::{
    IResult, Parser,
    branch::alt,
    bytes::complete::{tag, take_until, take_while, take_while1},
    character::complete::{char, multispace0, multispace1, satisfy},
    combinator::opt,
    sequence::{delimited, preceded},
};

use crate::error::{Error, Location, Result};

/// Deepest element nesting accepted (BSDF files nest 7 levels).
pub const MAX_DEPTH: usize = 64;
/// Most elements in one document (a Klems full file has about 300).
pub const MAX_ELEMENTS: usize = 1_000_000;

/// One element: name, attributes, the character data directly inside it (concatenated, as
/// `ezxml_txt` gives it) and its child elements in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub text: String,
    pub children: Vec<Element>,
    /// Byte offset of the `<` that opens the element.
    pub offset: usize,
    /// Byte offset where its character data starts (after the start tag's `>`).
    pub text_offset: usize,
}

impl Element {
    /// The name without a namespace prefix.
    pub fn local(&self) -> &str {
        local_name(&self.name)
    }

    /// The first child with this local name.
    pub fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.local() == name)
    }

    /// Every child with this local name, in order.
    pub fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element> {
        self.children.iter().filter(move |c| c.local() == name)
    }

    /// An attribute's value by local name.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| local_name(k) == name)
            .map(|(_, v)| v.as_str())
    }

    /// The trimmed text of the first child with this name (`None` when there is no such
    /// child; an empty string when it is empty, like `<Thickness/>`).
    pub fn child_text(&self, name: &str) -> Option<&str> {
        self.child(name).map(|c| c.text.trim())
    }
}

fn local_name(n: &str) -> &str {
    n.rsplit_once(':').map_or(n, |(_, l)| l)
}

/// Byte offsets to 1-based line numbers.
#[derive(Debug, Clone)]
pub struct Lines {
    newlines: Vec<usize>,
}

impl Lines {
    pub fn new(text: &str) -> Lines {
        Lines {
            newlines: text
                .bytes()
                .enumerate()
                .filter(|&(_, b)| b == b'\n')
                .map(|(i, _)| i)
                .collect(),
        }
    }

    /// The line of byte `offset`.
    pub fn line(&self, offset: usize) -> usize {
        self.newlines.partition_point(|&n| n < offset) + 1
    }
}

fn is_name_start(c: char) -> bool {
    c.is_alphabetic() || c == '_' || c == ':'
}

fn is_name_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | ':' | '-' | '.')
}

fn name(input: &str) -> IResult<&str, &str> {
    nom::combinator::recognize((satisfy(is_name_start), take_while(is_name_char))).parse(input)
}

/// `name = "value"` or `name = 'value'` (raw value, entities not yet expanded).
fn attribute(input: &str) -> IResult<&str, (&str, &str)> {
    let (input, _) = multispace1.parse(input)?;
    let (input, n) = name.parse(input)?;
    let (input, _) = (multispace0, char('='), multispace0).parse(input)?;
    let (input, v) = alt((
        delimited(char('"'), take_while(|c| c != '"' && c != '<'), char('"')),
        delimited(
            char('\''),
            take_while(|c| c != '\'' && c != '<'),
            char('\''),
        ),
    ))
    .parse(input)?;
    Ok((input, (n, v)))
}

/// What sits at the current position.
enum Token<'a> {
    /// `<name attr="v" ...>` or `<name .../>` (the flag).
    Start(&'a str, Vec<(&'a str, &'a str)>, bool),
    End(&'a str),
    /// Character data (raw, entities not expanded), or a CDATA section's content (verbatim).
    Text(&'a str),
    Cdata(&'a str),
    /// Comments and processing instructions (`<?xml ...?>`): skipped.
    Skip,
}

fn start_tag(input: &str) -> IResult<&str, Token<'_>> {
    let (input, n) = preceded(char('<'), name).parse(input)?;
    let mut attrs = Vec::new();
    let mut rest = input;
    while let Ok((r, a)) = attribute(rest) {
        attrs.push(a);
        rest = r;
    }
    let (rest, _) = multispace0.parse(rest)?;
    let (rest, close) = opt(char('/')).parse(rest)?;
    let (rest, _) = char('>').parse(rest)?;
    Ok((rest, Token::Start(n, attrs, close.is_some())))
}

fn end_tag(input: &str) -> IResult<&str, Token<'_>> {
    let (input, n) = delimited(tag("</"), name, (multispace0, char('>'))).parse(input)?;
    Ok((input, Token::End(n)))
}

fn comment(input: &str) -> IResult<&str, Token<'_>> {
    let (input, _) = delimited(tag("<!--"), take_until("-->"), tag("-->")).parse(input)?;
    Ok((input, Token::Skip))
}

fn instruction(input: &str) -> IResult<&str, Token<'_>> {
    let (input, _) = delimited(tag("<?"), take_until("?>"), tag("?>")).parse(input)?;
    Ok((input, Token::Skip))
}

fn cdata(input: &str) -> IResult<&str, Token<'_>> {
    let (input, t) = delimited(tag("<![CDATA["), take_until("]]>"), tag("]]>")).parse(input)?;
    Ok((input, Token::Cdata(t)))
}

fn text(input: &str) -> IResult<&str, Token<'_>> {
    let (input, t) = take_while1(|c| c != '<').parse(input)?;
    Ok((input, Token::Text(t)))
}

/// Expands `&lt; &gt; &amp; &quot; &apos; &#N; &#xN;`; the error names the bad reference.
fn unescape(raw: &str) -> std::result::Result<String, String> {
    if !raw.contains('&') {
        return Ok(raw.to_string());
    }
    let mut out = String::with_capacity(raw.len());
    let mut rest = raw;
    while let Some(i) = rest.find('&') {
        out.push_str(&rest[..i]);
        rest = &rest[i..];
        // Look for the ';' within 12 characters (a char boundary, whatever the text).
        let window = rest.char_indices().nth(12).map_or(rest.len(), |(i, _)| i);
        let Some(end) = rest[..window].find(';') else {
            return Err(format!(
                "an entity reference ending in ';' after '&' (found '{}')",
                rest.chars().take(12).collect::<String>()
            ));
        };
        let ent = &rest[1..end];
        let c = match ent {
            "lt" => Some('<'),
            "gt" => Some('>'),
            "amp" => Some('&'),
            "quot" => Some('"'),
            "apos" => Some('\''),
            _ => {
                let num = if let Some(h) = ent.strip_prefix("#x").or(ent.strip_prefix("#X")) {
                    u32::from_str_radix(h, 16).ok()
                } else if let Some(d) = ent.strip_prefix('#') {
                    d.parse::<u32>().ok()
                } else {
                    None
                };
                num.and_then(char::from_u32)
            }
        };
        match c {
            Some(c) => out.push(c),
            None => {
                return Err(format!(
                    "one of &lt; &gt; &amp; &quot; &apos; or a character number (found '&{ent};')"
                ));
            }
        }
        rest = &rest[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Parses a whole document and returns its root element. `file` names the input in errors.
pub fn parse(input: &str, file: &str) -> Result<Element> {
    let lines = Lines::new(input);
    let at = |off: usize, msg: String| Error::Parse {
        loc: Location::line(file, lines.line(off)),
        msg,
    };
    let body = input.strip_prefix('\u{feff}').unwrap_or(input);
    let base = input.len() - body.len();
    let mut rest = body;
    // Open elements, innermost last.
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    let mut count = 0usize;
    while !rest.is_empty() {
        let off = base + body.len() - rest.len();
        if rest.starts_with("<!DOCTYPE") || rest.starts_with("<!ENTITY") {
            return Err(at(
                off,
                "a BSDF file without a document type declaration (<!DOCTYPE ...> is not supported)"
                    .into(),
            ));
        }
        let parsed = if rest.starts_with("<!--") {
            comment(rest)
        } else if rest.starts_with("<?") {
            instruction(rest)
        } else if rest.starts_with("<![CDATA[") {
            cdata(rest)
        } else if rest.starts_with("</") {
            end_tag(rest)
        } else if rest.starts_with('<') {
            start_tag(rest)
        } else {
            text(rest)
        };
        let (next, token) = parsed.map_err(|_| {
            let what = if rest.starts_with("<!--") {
                "a comment closed by '-->'".to_string()
            } else if rest.starts_with("<?") {
                "a processing instruction closed by '?>'".to_string()
            } else if rest.starts_with("<![CDATA[") {
                "a CDATA section closed by ']]>'".to_string()
            } else if rest.starts_with("</") {
                "an end tag '</name>'".to_string()
            } else {
                "a start tag '<name attribute=\"value\" ...>' or '<name/>'".to_string()
            };
            let found: String = rest.chars().take(30).collect();
            at(off, format!("expected {what}, found '{found}'"))
        })?;
        let next_off = base + body.len() - next.len();
        match token {
            Token::Skip => {}
            Token::Text(t) | Token::Cdata(t) => {
                let raw = matches!(token, Token::Cdata(_));
                match stack.last_mut() {
                    Some(e) => {
                        let t = if raw {
                            t.to_string()
                        } else {
                            unescape(t).map_err(|m| at(off, format!("expected {m}")))?
                        };
                        e.text.push_str(&t);
                    }
                    None if t.trim().is_empty() => {}
                    None => {
                        return Err(at(
                            off,
                            format!(
                                "expected only markup outside the root element, found '{}'",
                                t.trim().chars().take(30).collect::<String>()
                            ),
                        ));
                    }
                }
            }
            Token::Start(n, attrs, empty) => {
                if root.is_some() {
                    return Err(at(
                        off,
                        format!("expected one root element, found a second one '<{n}>'"),
                    ));
                }
                count += 1;
                if count > MAX_ELEMENTS {
                    return Err(at(
                        off,
                        format!("expected at most {MAX_ELEMENTS} elements in a BSDF file"),
                    ));
                }
                if stack.len() >= MAX_DEPTH {
                    return Err(at(
                        off,
                        format!("expected elements nested at most {MAX_DEPTH} deep"),
                    ));
                }
                let mut attributes = Vec::with_capacity(attrs.len());
                for (k, v) in attrs {
                    let v = unescape(v)
                        .map_err(|m| at(off, format!("expected in attribute '{k}' {m}")))?;
                    attributes.push((k.to_string(), v));
                }
                let e = Element {
                    name: n.to_string(),
                    attrs: attributes,
                    text: String::new(),
                    children: Vec::new(),
                    offset: off,
                    text_offset: next_off,
                };
                if empty {
                    match stack.last_mut() {
                        Some(p) => p.children.push(e),
                        None => root = Some(e),
                    }
                } else {
                    stack.push(e);
                }
            }
            Token::End(n) => {
                let Some(e) = stack.pop() else {
                    return Err(at(off, format!("expected no end tag here, found '</{n}>'")));
                };
                if e.name != n {
                    return Err(at(
                        off,
                        format!(
                            "expected '</{}>' closing the element opened on line {}, found '</{n}>'",
                            e.name,
                            lines.line(e.offset)
                        ),
                    ));
                }
                match stack.last_mut() {
                    Some(p) => p.children.push(e),
                    None => root = Some(e),
                }
            }
        }
        rest = next;
    }
    if let Some(e) = stack.last() {
        return Err(at(
            input.len(),
            format!(
                "expected '</{}>' closing the element opened on line {}, found the end of the file",
                e.name,
                lines.line(e.offset)
            ),
        ));
    }
    root.ok_or_else(|| at(input.len(), "expected a root element, found none".into()))
}

/// `s` with `< > & "` escaped for element text or attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_attributes_text_and_skipped_markup() {
        let doc = "\u{feff}<?xml version=\"1.0\"?>\n<!-- c -->\n<a:Root x='1' b:y = \"&lt;2&gt;\">\n <Kid>t &amp; u</Kid><Kid/>\n <![CDATA[<raw>]]>\n</a:Root>\n";
        let r = parse(doc, "t.xml").unwrap();
        assert_eq!(r.local(), "Root");
        assert_eq!(r.attr("y"), Some("<2>"));
        assert_eq!(r.attr("x"), Some("1"));
        assert_eq!(r.children.len(), 2);
        assert_eq!(r.child_text("Kid"), Some("t & u"));
        assert!(r.text.contains("<raw>"));
        assert_eq!(Lines::new(doc).line(r.children[0].offset), 4);
    }

    #[test]
    fn errors_name_the_line_and_what_was_expected() {
        let cases = [
            ("<a>\n<b>\n</a>", "t.xml:3: expected '</b>'"),
            ("<a>\n<b>", "t.xml:2: expected '</b>'"),
            (
                "<!DOCTYPE a>\n<a/>",
                "t.xml:1: a BSDF file without a document type",
            ),
            ("<a>\n<b x=1/></a>", "t.xml:2: expected a start tag"),
            ("<a>&bogus;</a>", "t.xml:1: expected one of &lt;"),
            ("<a/><b/>", "t.xml:1: expected one root element"),
            ("", "t.xml:1: expected a root element"),
            ("<a><!-- x </a>", "t.xml:1: expected a comment"),
            ("x<a/>", "t.xml:1: expected only markup"),
        ];
        for (doc, want) in cases {
            let e = parse(doc, "t.xml").unwrap_err().to_string();
            assert!(e.starts_with(want), "{doc:?}: {e}");
        }
    }

    #[test]
    fn deep_nesting_is_refused_not_overflowed() {
        let doc = "<a>".repeat(100_000);
        let e = parse(&doc, "d.xml").unwrap_err().to_string();
        assert!(e.contains("nested at most"), "{e}");
    }

    #[test]
    fn multibyte_text_after_an_ampersand_does_not_panic() {
        // Found by tests/all/bsdf.rs's random bytes: a 12-byte window cut a character.
        let e = parse("<a>&V!\u{fffd}\u{fffd}\u{fffd}\u{fffd}</a>", "m.xml").unwrap_err();
        assert!(
            e.to_string().starts_with("m.xml:1: expected an entity"),
            "{e}"
        );
    }

    #[test]
    fn truncated_prefixes_never_panic() {
        let doc = "<?xml version=\"1.0\"?><W a=\"1\"><L>1, 2 &amp; 3</L><!-- c --><E/></W>";
        for i in 0..=doc.len() {
            if doc.is_char_boundary(i) {
                let _ = parse(&doc[..i], "p.xml");
            }
        }
    }
}
