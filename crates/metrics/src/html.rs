//! A self-contained HTML page frame for study reports: one file with its CSS inline and its
//! figures embedded (PNG as `data:` URIs, SVG inline), so it opens offline, mails as one
//! attachment and never fetches anything. `rmetrics report` builds the annual study's page
//! with it; rcalib's and rglare annual's reports can share it (same header, sections,
//! tables, figures, provenance and warnings blocks).
//!
//! ```
//! use rdaylight_metrics::html::{Page, table};
//! let mut p = Page::new("Study", "example room");
//! p.section("metrics", "Room metrics", &table(&["metric", "value"], &[vec!["DA".into(), "54 %".into()]], &[1]));
//! let html = p.render();
//! assert!(html.starts_with("<!DOCTYPE html>") && html.contains("<h2 id=\"metrics\">"));
//! ```

use crate::error::{Error, Result};
use base64::Engine as _;
use sha2::{Digest, Sha256};

/// Escape text for HTML content and attribute values.
pub fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            _ => o.push(c),
        }
    }
    o
}

const CSS: &str = "\
body{font-family:'DejaVu Sans',Verdana,Arial,sans-serif;margin:0;color:#222;background:#fff;line-height:1.4}\
header{background:#1f3b57;color:#fff;padding:18px 32px}header h1{margin:0;font-size:26px}\
header p{margin:4px 0 0;color:#d8e2ec}nav{padding:8px 32px;background:#eef2f6;font-size:14px}\
nav a{margin-right:14px;color:#1f3b57}main{padding:8px 32px 40px;max-width:1280px}\
h2{border-bottom:2px solid #1f3b57;padding-bottom:4px;margin-top:32px}\
table{border-collapse:collapse;margin:8px 0;font-size:14px}\
th,td{border:1px solid #ccd;padding:3px 8px;text-align:left;vertical-align:top}\
th{background:#eef2f6}td.n{text-align:right;font-variant-numeric:tabular-nums}\
figure{margin:16px 0}figure img,figure svg{max-width:100%;height:auto;border:1px solid #ddd}\
figcaption{font-size:14px;color:#444;margin-top:4px}code,pre{font-family:'DejaVu Sans Mono',monospace;font-size:13px}\
pre{background:#f6f8fa;padding:8px;overflow-x:auto;white-space:pre-wrap;word-break:break-all}\
.warn{background:#fff4e5;border-left:4px solid #e69500;padding:6px 12px;margin:6px 0}\
.ok{background:#eaf6ea;border-left:4px solid #3a3;padding:6px 12px}\
.scroll{max-height:480px;overflow:auto;display:inline-block}.grid{display:flex;flex-wrap:wrap;gap:12px}\
.grid figure{flex:1 1 560px;max-width:620px}";

/// A report page: a header and sections in order, with a navigation bar.
#[derive(Debug, Clone, Default)]
pub struct Page {
    title: String,
    subtitle: String,
    sections: Vec<(String, String, String)>,
}

impl Page {
    pub fn new(title: &str, subtitle: &str) -> Page {
        Page {
            title: title.into(),
            subtitle: subtitle.into(),
            sections: Vec::new(),
        }
    }

    /// Append a section: `id` (anchor), heading text, body HTML (already escaped).
    pub fn section(&mut self, id: &str, heading: &str, body: &str) {
        self.sections.push((id.into(), heading.into(), body.into()));
    }

    /// The whole document.
    pub fn render(&self) -> String {
        let mut s = format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <title>{}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<header><h1>{}</h1><p>{}</p></header>\n<nav>",
            escape(&self.title),
            escape(&self.title),
            escape(&self.subtitle)
        );
        for (id, h, _) in &self.sections {
            s += &format!("<a href=\"#{}\">{}</a>", escape(id), escape(h));
        }
        s += "</nav>\n<main>\n";
        for (id, h, body) in &self.sections {
            s += &format!("<h2 id=\"{}\">{}</h2>\n{body}\n", escape(id), escape(h));
        }
        s += "</main>\n</body>\n</html>\n";
        s
    }
}

/// A table; columns listed in `numeric` are right-aligned. Cells are escaped.
pub fn table(headers: &[&str], rows: &[Vec<String>], numeric: &[usize]) -> String {
    let mut s = String::from("<table><thead><tr>");
    for h in headers {
        s += &format!("<th>{}</th>", escape(h));
    }
    s += "</tr></thead><tbody>";
    for r in rows {
        s += "<tr>";
        for (k, c) in r.iter().enumerate() {
            if numeric.contains(&k) {
                s += &format!("<td class=\"n\">{}</td>", escape(c));
            } else {
                s += &format!("<td>{}</td>", escape(c));
            }
        }
        s += "</tr>";
    }
    s + "</tbody></table>"
}

/// A PNG figure embedded as a `data:` URI, with alternative text and a caption.
pub fn figure_png(png: &[u8], alt: &str, caption: &str) -> String {
    format!(
        "<figure><img src=\"data:image/png;base64,{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
        base64::engine::general_purpose::STANDARD.encode(png),
        escape(alt),
        escape(caption)
    )
}

/// An SVG figure inline (its XML declaration, if any, dropped).
pub fn figure_svg(svg: &str, caption: &str) -> String {
    let body = match svg.find("<svg") {
        Some(i) => &svg[i..],
        None => svg,
    };
    format!(
        "<figure>{body}<figcaption>{}</figcaption></figure>",
        escape(caption)
    )
}

/// Key-value pairs as a two-column table.
pub fn definitions(pairs: &[(String, String)]) -> String {
    let rows: Vec<Vec<String>> = pairs
        .iter()
        .map(|(k, v)| vec![k.clone(), v.clone()])
        .collect();
    table(&["", ""], &rows, &[]).replace("<thead><tr><th></th><th></th></tr></thead>", "")
}

/// Warnings as highlighted paragraphs ("none" in green when empty).
pub fn warnings(list: &[String]) -> String {
    if list.is_empty() {
        return "<p class=\"ok\">No warnings.</p>".into();
    }
    list.iter()
        .map(|w| format!("<p class=\"warn\">{}</p>", escape(w)))
        .collect()
}

/// A file's SHA-256 (hex) and size in bytes.
pub fn sha256_file(path: &str) -> Result<(String, u64)> {
    use std::io::Read;
    let mut f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    let mut n = 0u64;
    loop {
        let k = f.read(&mut buf).map_err(|e| Error::io(path, e))?;
        if k == 0 {
            break;
        }
        n += k as u64;
        h.update(&buf[..k]);
    }
    let hex: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    Ok((hex, n))
}

/// Provenance block: inputs with their SHA-256 and size, tool versions, exact commands.
pub fn provenance(inputs: &[String], tools: &[String], commands: &[String]) -> Result<String> {
    let mut rows = Vec::new();
    for p in inputs {
        let (hash, size) = sha256_file(p)?;
        rows.push(vec![p.clone(), size.to_string(), hash]);
    }
    let mut s = String::from("<h3>Inputs</h3>");
    s += &table(&["file", "bytes", "SHA-256"], &rows, &[1]);
    if !tools.is_empty() {
        s += "<h3>Tools</h3><ul>";
        for t in tools {
            s += &format!("<li><code>{}</code></li>", escape(t));
        }
        s += "</ul>";
    }
    if !commands.is_empty() {
        s += "<h3>Commands, in order</h3><pre>";
        for c in commands {
            s += &escape(c);
            s += "\n";
        }
        s += "</pre>";
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_frames() {
        assert_eq!(
            escape("<a href=\"x\">&'"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
        let mut p = Page::new("T <1>", "sub");
        p.section("a", "A & B", &table(&["x"], &[vec!["<b>".into()]], &[0]));
        let h = p.render();
        assert!(h.contains("<title>T &lt;1&gt;</title>"));
        assert!(h.contains("<a href=\"#a\">A &amp; B</a>"));
        assert!(h.contains("<td class=\"n\">&lt;b&gt;</td>"));
        assert!(!h.contains("http"), "no external reference");
    }

    #[test]
    fn sha256_of_known_bytes() {
        let d = tempfile::tempdir().unwrap();
        let f = d.path().join("abc");
        std::fs::write(&f, b"abc").unwrap();
        let (h, n) = sha256_file(f.to_str().unwrap()).unwrap();
        // FIPS 180-2 test vector for "abc".
        assert_eq!(
            h,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_eq!(n, 3);
        let fig = figure_png(&[1, 2, 3], "a", "c");
        assert!(fig.contains("data:image/png;base64,AQID"));
    }
}
