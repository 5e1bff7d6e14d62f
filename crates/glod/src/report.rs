//! What `rglod objects` prints: one TSV row (or JSON record) per object, shell first.

use std::fmt::Write;

use serde::Serialize;

use crate::objects::{Analysis, GlodObject};

/// Header of the TSV table.
pub const TSV_HEADER: &str =
    "object\tprimitives\tcx\tcy\tcz\tax1\tax2\tax3\tsize1\tsize2\tsize3\tarea_m2\tlevel";

fn f(v: f64) -> String {
    // 6 decimals: micrometres and square micrometres, beyond any survey.
    let s = format!("{v:.6}");
    if s == "-0.000000" {
        "0.000000".into()
    } else {
        s
    }
}

fn axis(v: [f64; 3]) -> String {
    format!("{},{},{}", f(v[0]), f(v[1]), f(v[2]))
}

fn row(o: &GlodObject) -> String {
    let b = &o.obb;
    format!(
        "{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}",
        o.id,
        o.members.len(),
        f(b.center[0]),
        f(b.center[1]),
        f(b.center[2]),
        axis(b.axes[0]),
        axis(b.axes[1]),
        axis(b.axes[2]),
        f(b.size[0]),
        f(b.size[1]),
        f(b.size[2]),
        f(o.area),
        o.level
    )
}

/// The table: a header, a `(shell)` row (level 0, no box), one row per object. Axes are
/// `x,y,z` unit vectors; sizes are full side lengths (m) along them.
pub fn tsv(a: &Analysis) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{TSV_HEADER}");
    let _ = writeln!(s, "(shell)\t{}\t\t\t\t\t\t\t\t\t\t\t0", a.shell.len());
    for o in &a.objects {
        let _ = writeln!(s, "{}", row(o));
    }
    s
}

#[derive(Serialize)]
struct Json<'a> {
    shell: &'a [usize],
    objects: &'a [GlodObject],
}

/// The same as JSON: `{"shell": [primitive indices], "objects": [{id, members, obb, area,
/// level}]}`.
pub fn json(a: &Analysis) -> String {
    serde_json::to_string_pretty(&Json {
        shell: &a.shell,
        objects: &a.objects,
    })
    .unwrap_or_else(|_| "{}".into())
}
