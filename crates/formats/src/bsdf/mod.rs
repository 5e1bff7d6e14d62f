//! # BSDF XML files (LBNL WINDOW 6 schema, as Radiance reads them)
//!
//! The `BSDF` and `aBSDF` materials, `dctimestep` and `rfluxmtx`'s 3-phase chain read a
//! window system's optical data from XML: `<WindowElement>/<Optical>/<Layer>` holds a
//! `<Material>` (name, thickness with its `unit`), a `<DataDefinition>` (the
//! `<IncidentDataStructure>` and the `<AngleBasis>` ring layouts) and one `<WavelengthData>`
//! per channel, each with `<WavelengthDataBlock>`s of one direction
//! (`<WavelengthDataDirection>`) and its `<ScatteringData>`. This module reads that subset
//! into [`BsdfXml`] and writes it back ([`BsdfXml::to_xml`]); evaluating the BSDF is
//! physics' job (`rdaylight_physics::material::bsdf`).
//!
//! What Radiance uses (`src/common/bsdf.c` `SDloadFile`, `bsdf_m.c` `SDloadMtx`, `bsdf_t.c`
//! `SDloadTre`; read to learn the format, not copied):
//! - Channels by the `<Wavelength>` text: `Visible` is CIE Y (photopic); Klems files add
//!   `CIE-X` and `CIE-Z` for colour, tensor trees `CIE-u` and `CIE-v`. `Solar` and anything
//!   else are ignored by Radiance; we keep them as [`Channel::Other`].
//! - `IncidentDataStructure` `Columns`: `<ScatteringData>` lists the matrix row by row with
//!   rows = outgoing patches (`RowAngleBasis`) and columns = incident patches
//!   (`ColumnAngleBasis`); `Rows`: the transpose (each row one incident patch).
//!   `TensorTree3`/`TensorTree4`: nested `{ ... }` trees over the Shirley-Chiu square
//!   (`AngleBasis` `LBNL/Shirley-Chiu`).
//! - Values are separated by white space and/or commas; Radiance clamps negatives to 0 when
//!   it loads them ([`KlemsMatrix::value`] does too; the raw numbers stay in the struct).
//! - Front and back are WINDOW's (front = outside); Radiance swaps them to its own
//!   convention when it loads (front = the side the surface normal points to). The names
//!   here are the file's.
//!
//! Sizes are bounded: [`MAX_FILE_BYTES`], the XML reader's depth and element limits, and
//! at most [`MAX_TREE_DEPTH`] tensor-tree levels.

pub mod xml;

use std::path::Path;

use crate::error::{Error, Location, Result};
use xml::{Element, Lines};

/// Largest BSDF file read (a Klems full file with colour is about 5 MB; tensor trees of
/// rank 4 at 2^7 can reach a few hundred MB).
pub const MAX_FILE_BYTES: u64 = 1 << 30;
/// Deepest tensor-tree nesting accepted (`bsdf2ttree -g 7` makes 7 levels).
pub const MAX_TREE_DEPTH: usize = 24;
/// Largest angle basis (patches) and matrix (values) accepted.
pub const MAX_BASIS_PATCHES: usize = 100_000;

/// A whole BSDF file.
#[derive(Debug, Clone, PartialEq)]
pub struct BsdfXml {
    /// `<WindowElementType>` (`System` from wrapBSDF), when present.
    pub element_type: Option<String>,
    pub layers: Vec<Layer>,
}

/// One `<Layer>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    pub material: Material,
    pub structure: DataStructure,
    /// The `<AngleBasis>` definitions of `<DataDefinition>` (Klems files; empty for trees).
    pub bases: Vec<AngleBasis>,
    /// Every `<WavelengthDataBlock>`, in file order.
    pub components: Vec<Component>,
}

/// `<Material>`: lengths in metres (converted from the `unit` attribute as Radiance's
/// `to_meters`: Meter, Foot, Inch, Centimeter, Millimeter; none = metres).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Material {
    pub name: Option<String>,
    pub manufacturer: Option<String>,
    pub thickness: Option<f64>,
    pub width: Option<f64>,
    pub height: Option<f64>,
}

/// `<IncidentDataStructure>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataStructure {
    /// Klems matrix listed with one row per outgoing patch (columns are incident).
    Columns,
    /// Klems matrix listed with one row per incident patch.
    Rows,
    /// Isotropic tensor tree (rank 3).
    TensorTree3,
    /// Anisotropic tensor tree (rank 4).
    TensorTree4,
}

impl DataStructure {
    pub fn name(self) -> &'static str {
        match self {
            DataStructure::Columns => "Columns",
            DataStructure::Rows => "Rows",
            DataStructure::TensorTree3 => "TensorTree3",
            DataStructure::TensorTree4 => "TensorTree4",
        }
    }
}

/// One `<AngleBasis>`: a name and its rings (`<AngleBasisBlock>`s).
#[derive(Debug, Clone, PartialEq)]
pub struct AngleBasis {
    pub name: String,
    pub rings: Vec<Ring>,
}

/// One `<AngleBasisBlock>`: its `<Theta>` (centre), `<nPhis>` and `<ThetaBounds>` in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ring {
    pub theta: f64,
    pub nphis: usize,
    pub lower: f64,
    pub upper: f64,
}

impl AngleBasis {
    /// Number of patches.
    pub fn len(&self) -> usize {
        self.rings.iter().map(|r| r.nphis).sum()
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Ring upper bounds (degrees) and patches per ring, the form
    /// `rdaylight_physics::geometry::klems::KlemsBasis::from_rings` takes.
    pub fn upper_and_nphis(&self) -> (Vec<f64>, Vec<usize>) {
        (
            self.rings.iter().map(|r| r.upper).collect(),
            self.rings.iter().map(|r| r.nphis).collect(),
        )
    }
}

/// The channel a `<WavelengthData>` block holds (`<Wavelength>`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Channel {
    /// `Visible`: photopic, CIE Y.
    Visible,
    CieX,
    CieZ,
    /// Tensor trees' chromaticity channels.
    CieU,
    CieV,
    /// `Solar`, `NIR` or anything else: kept, unused by Radiance.
    Other(String),
}

impl Channel {
    fn from_text(t: &str) -> Channel {
        match t.to_ascii_lowercase().as_str() {
            "visible" => Channel::Visible,
            "cie-x" => Channel::CieX,
            "cie-z" => Channel::CieZ,
            "cie-u" => Channel::CieU,
            "cie-v" => Channel::CieV,
            _ => Channel::Other(t.to_string()),
        }
    }
    pub fn name(&self) -> &str {
        match self {
            Channel::Visible => "Visible",
            Channel::CieX => "CIE-X",
            Channel::CieZ => "CIE-Z",
            Channel::CieU => "CIE-u",
            Channel::CieV => "CIE-v",
            Channel::Other(s) => s,
        }
    }
}

/// `<WavelengthDataDirection>`, WINDOW's names (front = outside; see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    TransmissionFront,
    TransmissionBack,
    ReflectionFront,
    ReflectionBack,
}

impl Direction {
    pub const ALL: [Direction; 4] = [
        Direction::TransmissionFront,
        Direction::TransmissionBack,
        Direction::ReflectionFront,
        Direction::ReflectionBack,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Direction::TransmissionFront => "Transmission Front",
            Direction::TransmissionBack => "Transmission Back",
            Direction::ReflectionFront => "Reflection Front",
            Direction::ReflectionBack => "Reflection Back",
        }
    }
    fn from_text(t: &str) -> Option<Direction> {
        Direction::ALL
            .into_iter()
            .find(|d| d.name().eq_ignore_ascii_case(t))
    }
    pub fn is_transmission(self) -> bool {
        matches!(
            self,
            Direction::TransmissionFront | Direction::TransmissionBack
        )
    }
}

/// One `<WavelengthDataBlock>` with its channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    pub channel: Channel,
    /// `<Wavelength unit=...>` (`Integral` from wrapBSDF), kept for writing back.
    pub unit: Option<String>,
    /// `<DetectorSpectrum>` of the `<WavelengthData>`, when given.
    pub detector: Option<String>,
    pub direction: Direction,
    pub data: ScatteringData,
    /// Line of the `<ScatteringData>` element, for later errors.
    pub line: usize,
}

/// The numbers of a block.
#[derive(Debug, Clone, PartialEq)]
pub enum ScatteringData {
    Klems(KlemsMatrix),
    Tree(TensorTree),
}

/// A Klems matrix BSDF (1/sr), stored Radiance's way: `values[out * n_in + inc]`.
#[derive(Debug, Clone, PartialEq)]
pub struct KlemsMatrix {
    /// `<ColumnAngleBasis>`: the incident directions' basis name.
    pub incident_basis: String,
    /// `<RowAngleBasis>`: the outgoing directions' basis name.
    pub outgoing_basis: String,
    pub n_in: usize,
    pub n_out: usize,
    /// Raw values (negatives kept), outgoing-major.
    pub values: Vec<f64>,
}

impl KlemsMatrix {
    /// The BSDF for outgoing patch `out` and incident patch `inc`, negatives clamped to 0 as
    /// Radiance's loader does.
    pub fn value(&self, out: usize, inc: usize) -> f64 {
        self.values[out * self.n_in + inc].max(0.0)
    }
}

/// A tensor tree (`TensorTree3`: isotropic, `TensorTree4`: anisotropic) over the
/// Shirley-Chiu square of incident and outgoing directions.
#[derive(Debug, Clone, PartialEq)]
pub struct TensorTree {
    /// 3 or 4.
    pub rank: usize,
    /// `<AngleBasis>` of the block (`LBNL/Shirley-Chiu`).
    pub basis: String,
    pub root: TreeNode,
}

/// A tree node: `2^rank` children, or a leaf grid of `2^(rank k)` values (`k` = `log2`
/// cells per dimension), listed with the last dimension fastest.
#[derive(Debug, Clone, PartialEq)]
pub enum TreeNode {
    Branch(Vec<TreeNode>),
    Leaf { log2: u32, values: Vec<f32> },
}

/// Radiance's `to_meters`.
fn to_meters(unit: Option<&str>) -> Option<f64> {
    match unit.map(str::to_ascii_lowercase).as_deref() {
        None | Some("meter") => Some(1.0),
        Some("foot") => Some(0.3048),
        Some("inch") => Some(0.0254),
        Some("centimeter") => Some(0.01),
        Some("millimeter") => Some(0.001),
        Some(_) => None,
    }
}

/// Reads a BSDF file (at most [`MAX_FILE_BYTES`]).
pub fn load(path: &Path) -> Result<BsdfXml> {
    use std::io::Read;
    let name = path.display().to_string();
    let io = |source| Error::Io {
        path: name.clone(),
        source,
    };
    let f = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    f.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(Error::Parse {
            loc: Location::file(&name),
            msg: format!("expected a BSDF file of at most {MAX_FILE_BYTES} bytes"),
        });
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        let off = e.utf8_error().valid_up_to();
        let line = Lines::new(&String::from_utf8_lossy(&e.as_bytes()[..off])).line(off);
        Error::Parse {
            loc: Location::line(&name, line),
            msg: "expected UTF-8 XML text, found invalid bytes".into(),
        }
    })?;
    parse(&text, &name)
}

/// Parses BSDF XML text; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<BsdfXml> {
    let root = xml::parse(text, file)?;
    let lines = Lines::new(text);
    let cx = Cx {
        file,
        lines: &lines,
    };
    if root.local() != "WindowElement" {
        return Err(cx.err(
            &root,
            format!(
                "expected the root element <WindowElement>, found <{}>",
                root.name
            ),
        ));
    }
    if let Some(ft) = root.child("FileType") {
        if ft.text.trim() != "BSDF" {
            return Err(cx.err(
                ft,
                format!(
                    "expected <FileType>BSDF</FileType>, found '{}'",
                    ft.text.trim()
                ),
            ));
        }
    }
    let optical = root.child("Optical").ok_or_else(|| {
        cx.err(
            &root,
            "expected an <Optical> element with at least one <Layer> in <WindowElement>".into(),
        )
    })?;
    let mut layers = Vec::new();
    for l in optical.children_named("Layer") {
        layers.push(cx.layer(l)?);
    }
    if layers.is_empty() {
        return Err(cx.err(optical, "expected at least one <Layer> in <Optical>".into()));
    }
    Ok(BsdfXml {
        element_type: root.child_text("WindowElementType").map(str::to_string),
        layers,
    })
}

struct Cx<'a> {
    file: &'a str,
    lines: &'a Lines,
}

impl Cx<'_> {
    fn err(&self, e: &Element, msg: String) -> Error {
        self.err_at(e.offset, msg)
    }
    fn err_at(&self, off: usize, msg: String) -> Error {
        Error::Parse {
            loc: Location::line(self.file, self.lines.line(off)),
            msg,
        }
    }

    /// A required child's trimmed, non-empty text.
    fn required<'e>(&self, e: &'e Element, name: &str) -> Result<(&'e Element, &'e str)> {
        match e.child(name) {
            Some(c) if !c.text.trim().is_empty() => Ok((c, c.text.trim())),
            Some(c) => Err(self.err(c, format!("expected text in <{name}>, found it empty"))),
            None => Err(self.err(e, format!("expected <{name}> in <{}>", e.local()))),
        }
    }

    fn number(&self, e: &Element, name: &str) -> Result<f64> {
        let (c, t) = self.required(e, name)?;
        t.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.err(c, format!("expected a number in <{name}>, found '{t}'")))
    }

    /// An optional length in metres (empty elements such as `<Thickness/>` count as absent).
    fn length(&self, m: &Element, name: &str) -> Result<Option<f64>> {
        let Some(c) = m.child(name) else {
            return Ok(None);
        };
        let t = c.text.trim();
        if t.is_empty() {
            return Ok(None);
        }
        let v = t
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v >= 0.0)
            .ok_or_else(|| {
                self.err(
                    c,
                    format!("expected a non-negative number in <{name}>, found '{t}'"),
                )
            })?;
        let f = to_meters(c.attr("unit")).ok_or_else(|| {
            self.err(
                c,
                format!(
                    "expected unit Meter, Foot, Inch, Centimeter or Millimeter in <{name}>, found '{}'",
                    c.attr("unit").unwrap_or("")
                ),
            )
        })?;
        Ok(Some(v * f))
    }

    fn layer(&self, l: &Element) -> Result<Layer> {
        let material = match l.child("Material") {
            Some(m) => {
                let text = |n: &str| {
                    m.child_text(n)
                        .filter(|t| !t.is_empty())
                        .map(str::to_string)
                };
                Material {
                    name: text("Name"),
                    manufacturer: text("Manufacturer"),
                    thickness: self.length(m, "Thickness")?,
                    width: self.length(m, "Width")?,
                    height: self.length(m, "Height")?,
                }
            }
            None => Material::default(),
        };
        let dd = l.child("DataDefinition").ok_or_else(|| {
            self.err(
                l,
                "expected a <DataDefinition> in <Layer> (a BSDF file with data)".into(),
            )
        })?;
        let structure = match dd.child("IncidentDataStructure") {
            None => {
                return Err(self.err(
                    dd,
                    "expected an <IncidentDataStructure> (Columns, Rows, TensorTree3 or TensorTree4) in <DataDefinition>: this file has no BSDF data".into(),
                ));
            }
            Some(s) => match s.text.trim().to_ascii_lowercase().as_str() {
                "columns" => DataStructure::Columns,
                "rows" => DataStructure::Rows,
                "tensortree3" => DataStructure::TensorTree3,
                "tensortree4" => DataStructure::TensorTree4,
                t => {
                    return Err(self.err(
                        s,
                        format!("expected Columns, Rows, TensorTree3 or TensorTree4 in <IncidentDataStructure>, found '{t}'"),
                    ));
                }
            },
        };
        let mut bases = Vec::new();
        for ab in dd.children_named("AngleBasis") {
            bases.push(self.basis(ab)?);
        }
        let mut components = Vec::new();
        for wd in l.children_named("WavelengthData") {
            let (wl, wtext) = self.required(wd, "Wavelength")?;
            let channel = Channel::from_text(wtext);
            let unit = wl.attr("unit").map(str::to_string);
            let detector = wd
                .child_text("DetectorSpectrum")
                .filter(|t| !t.is_empty())
                .map(str::to_string);
            for b in wd.children_named("WavelengthDataBlock") {
                let (dc, dtext) = self.required(b, "WavelengthDataDirection")?;
                let direction = Direction::from_text(dtext).ok_or_else(|| {
                    self.err(dc, format!("expected Transmission Front, Transmission Back, Reflection Front or Reflection Back in <WavelengthDataDirection>, found '{dtext}'"))
                })?;
                let sd = b.child("ScatteringData").ok_or_else(|| {
                    self.err(
                        b,
                        "expected <ScatteringData> in <WavelengthDataBlock>".into(),
                    )
                })?;
                let data = match structure {
                    DataStructure::Columns | DataStructure::Rows => {
                        ScatteringData::Klems(self.klems(b, sd, structure, &bases)?)
                    }
                    DataStructure::TensorTree3 | DataStructure::TensorTree4 => {
                        let rank = if structure == DataStructure::TensorTree3 {
                            3
                        } else {
                            4
                        };
                        let (_, basis) = self.required(b, "AngleBasis")?;
                        ScatteringData::Tree(TensorTree {
                            rank,
                            basis: basis.to_string(),
                            root: self.tree(sd, rank)?,
                        })
                    }
                };
                components.push(Component {
                    channel: channel.clone(),
                    unit: unit.clone(),
                    detector: detector.clone(),
                    direction,
                    data,
                    line: self.lines.line(sd.offset),
                });
            }
        }
        if components.is_empty() {
            return Err(self.err(
                l,
                "expected at least one <WavelengthData> with a <WavelengthDataBlock> in <Layer>"
                    .into(),
            ));
        }
        Ok(Layer {
            material,
            structure,
            bases,
            components,
        })
    }

    fn basis(&self, ab: &Element) -> Result<AngleBasis> {
        let (_, name) = self.required(ab, "AngleBasisName")?;
        let mut rings: Vec<Ring> = Vec::new();
        let mut total = 0usize;
        for b in ab.children_named("AngleBasisBlock") {
            let tb = b
                .child("ThetaBounds")
                .ok_or_else(|| self.err(b, "expected <ThetaBounds> in <AngleBasisBlock>".into()))?;
            let upper = self.number(tb, "UpperTheta")?;
            let lower = match tb.child("LowerTheta") {
                Some(_) => self.number(tb, "LowerTheta")?,
                None => rings.last().map_or(0.0, |r| r.upper),
            };
            let (nc, nt) = self.required(b, "nPhis")?;
            let nphis = nt
                .parse::<usize>()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| {
                    self.err(
                        nc,
                        format!("expected a whole number >= 1 in <nPhis>, found '{nt}'"),
                    )
                })?;
            let expect_lower = rings.last().map_or(0.0, |r| r.upper);
            if (lower - expect_lower).abs() > 1e-6 * expect_lower.max(1.0) {
                return Err(self.err(
                    tb,
                    format!("expected <LowerTheta> {expect_lower} (the previous ring's upper bound), found {lower}"),
                ));
            }
            if !(upper > lower && upper <= 90.0) {
                return Err(self.err(
                    tb,
                    format!("expected <UpperTheta> above {lower} and at most 90, found {upper}"),
                ));
            }
            total += nphis;
            if total > MAX_BASIS_PATCHES {
                return Err(self.err(
                    nc,
                    format!("expected an angle basis of at most {MAX_BASIS_PATCHES} patches"),
                ));
            }
            let theta = match b.child("Theta") {
                Some(_) => self.number(b, "Theta")?,
                None => 0.5 * (lower + upper),
            };
            rings.push(Ring {
                theta,
                nphis,
                lower,
                upper,
            });
        }
        match rings.last() {
            None => {
                return Err(self.err(
                    ab,
                    format!("expected <AngleBasisBlock>s in angle basis '{name}'"),
                ));
            }
            Some(r) if (r.upper - 90.0).abs() > 1e-6 => {
                return Err(self.err(
                    ab,
                    format!(
                        "expected angle basis '{name}' to end at 90 degrees, found {}",
                        r.upper
                    ),
                ));
            }
            _ => {}
        }
        Ok(AngleBasis {
            name: name.to_string(),
            rings,
        })
    }

    fn klems(
        &self,
        block: &Element,
        sd: &Element,
        structure: DataStructure,
        bases: &[AngleBasis],
    ) -> Result<KlemsMatrix> {
        let (cc, col) = self.required(block, "ColumnAngleBasis")?;
        let (rc, row) = self.required(block, "RowAngleBasis")?;
        let find = |e: &Element, n: &str, what: &str| {
            bases
                .iter()
                .find(|b| b.name.eq_ignore_ascii_case(n))
                .ok_or_else(|| {
                    self.err(
                        e,
                        format!("expected <{what}> to name an <AngleBasis> of <DataDefinition>, found '{n}'"),
                    )
                })
        };
        let n_in = find(cc, col, "ColumnAngleBasis")?.len();
        let n_out = find(rc, row, "RowAngleBasis")?.len();
        let want = n_in * n_out;
        let file_order = self.numbers(sd, want)?;
        let values = match structure {
            DataStructure::Columns => file_order,
            // Each listed row is one incident patch: transpose to outgoing-major.
            _ => {
                let mut v = vec![0.0; want];
                for (i, x) in file_order.into_iter().enumerate() {
                    let (inc, out) = (i / n_out, i % n_out);
                    v[out * n_in + inc] = x;
                }
                v
            }
        };
        Ok(KlemsMatrix {
            incident_basis: col.to_string(),
            outgoing_basis: row.to_string(),
            n_in,
            n_out,
            values,
        })
    }

    /// Exactly `want` numbers separated by white space and/or commas.
    fn numbers(&self, sd: &Element, want: usize) -> Result<Vec<f64>> {
        let mut out = Vec::with_capacity(want);
        let text = &sd.text;
        let mut pos = 0usize;
        for tok in text.split(|c: char| c.is_whitespace() || c == ',') {
            let start = pos;
            pos += tok.len() + 1;
            if tok.is_empty() {
                continue;
            }
            let off = sd.text_offset + start;
            if out.len() == want {
                return Err(self.err_at(
                    off,
                    format!("expected {want} values in <ScatteringData>, found more ('{tok}')"),
                ));
            }
            let v = tok
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    self.err_at(
                        off,
                        format!("expected a number in <ScatteringData>, found '{tok}'"),
                    )
                })?;
            out.push(v);
        }
        if out.len() != want {
            return Err(self.err(
                sd,
                format!(
                    "expected {want} values in <ScatteringData> (row x column basis sizes), found {}",
                    out.len()
                ),
            ));
        }
        Ok(out)
    }

    /// A `{ ... }` tree as `bsdf_t.c` reads it: a node is `{` then either `2^rank` nodes or
    /// `2^(rank k)` numbers, then `}`, optionally followed by a comma.
    fn tree(&self, sd: &Element, rank: usize) -> Result<TreeNode> {
        let text = sd.text.as_str();
        let mut p = TreeReader {
            text,
            pos: 0,
            rank,
            cx: self,
            base: sd.text_offset,
        };
        p.skip_space();
        if p.pos == text.len() {
            return Err(self.err(
                sd,
                "expected tensor-tree data '{ ... }' in <ScatteringData>, found it empty".into(),
            ));
        }
        let root = p.node(0)?;
        p.skip_space();
        if p.pos != text.len() {
            return Err(p.error("the end of <ScatteringData> after the tree's closing '}'"));
        }
        Ok(root)
    }
}

struct TreeReader<'a, 'c> {
    text: &'a str,
    pos: usize,
    rank: usize,
    cx: &'c Cx<'c>,
    base: usize,
}

impl TreeReader<'_, '_> {
    fn skip_space(&mut self) {
        let rest = &self.text[self.pos..];
        self.pos += rest.len() - rest.trim_start().len();
    }
    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }
    fn error(&self, expected: &str) -> Error {
        let found: String = self.text[self.pos..].chars().take(20).collect();
        let found = if found.is_empty() {
            "the end of the data".to_string()
        } else {
            format!("'{found}'")
        };
        self.cx.err_at(
            self.base + self.pos,
            format!("expected {expected} in the tensor tree, found {found}"),
        )
    }
    fn eat(&mut self, c: u8) -> bool {
        self.skip_space();
        if self.peek() == Some(c) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    /// One node; its closing brace and an optional comma are consumed.
    fn node(&mut self, depth: usize) -> Result<TreeNode> {
        if depth >= MAX_TREE_DEPTH {
            return Err(self.error(&format!("at most {MAX_TREE_DEPTH} nested levels")));
        }
        if !self.eat(b'{') {
            return Err(self.error("'{'"));
        }
        self.skip_space();
        let node = if self.peek() == Some(b'{') {
            let n = 1usize << self.rank;
            let mut kids = Vec::with_capacity(n);
            for _ in 0..n {
                kids.push(self.node(depth + 1)?);
            }
            TreeNode::Branch(kids)
        } else {
            let start = self.pos;
            let mut values = Vec::new();
            loop {
                self.skip_space();
                match self.peek() {
                    Some(b'}') | None => break,
                    _ => {}
                }
                let rest = &self.text[self.pos..];
                let len = rest
                    .find(|c: char| c.is_whitespace() || c == ',' || c == '}' || c == '{')
                    .unwrap_or(rest.len());
                let tok = &rest[..len];
                let v = tok
                    .parse::<f32>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| self.error("a number or '}'"))?;
                values.push(v);
                self.pos += len;
                self.eat(b',');
            }
            let n = values.len();
            // n must be 2^(rank k), k >= 0.
            let log2 = (0..=24u32).find(|&k| {
                (k as usize * self.rank) < usize::BITS as usize
                    && n == 1usize << (k as usize * self.rank)
            });
            let Some(log2) = log2 else {
                self.pos = start;
                return Err(self.error(&format!(
                    "a leaf of 2^({} k) values (1, {}, {}, ...), not {n}",
                    self.rank,
                    1usize << self.rank,
                    1usize << (2 * self.rank)
                )));
            };
            TreeNode::Leaf { log2, values }
        };
        if !self.eat(b'}') {
            return Err(self.error("'}'"));
        }
        self.eat(b',');
        Ok(node)
    }
}

impl BsdfXml {
    /// The file as WINDOW XML (what `wrapBSDF` writes, minus its comments); [`parse`] reads
    /// it back to an equal value (Klems values in `Columns` order; numbers in shortest
    /// round-trip form).
    pub fn to_xml(&self) -> String {
        use std::fmt::Write;
        let esc = xml::escape;
        let mut s = String::new();
        s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        s.push_str("<WindowElement xmlns=\"http://windows.lbl.gov\">\n");
        if let Some(t) = &self.element_type {
            let _ = writeln!(s, "<WindowElementType>{}</WindowElementType>", esc(t));
        }
        s.push_str("<FileType>BSDF</FileType>\n<Optical>\n");
        for l in &self.layers {
            s.push_str("<Layer>\n\t<Material>\n");
            let m = &l.material;
            for (tag, v) in [("Name", &m.name), ("Manufacturer", &m.manufacturer)] {
                if let Some(v) = v {
                    let _ = writeln!(s, "\t\t<{tag}>{}</{tag}>", esc(v));
                }
            }
            for (tag, v) in [
                ("Thickness", m.thickness),
                ("Width", m.width),
                ("Height", m.height),
            ] {
                if let Some(v) = v {
                    let _ = writeln!(s, "\t\t<{tag} unit=\"Meter\">{v}</{tag}>");
                }
            }
            s.push_str("\t</Material>\n\t<DataDefinition>\n");
            // Klems data is always written in `Columns` order.
            let structure = match l.structure {
                DataStructure::Rows => DataStructure::Columns,
                d => d,
            };
            let _ = writeln!(
                s,
                "\t\t<IncidentDataStructure>{}</IncidentDataStructure>",
                structure.name()
            );
            for b in &l.bases {
                let _ = writeln!(
                    s,
                    "\t\t<AngleBasis>\n\t\t\t<AngleBasisName>{}</AngleBasisName>",
                    esc(&b.name)
                );
                for r in &b.rings {
                    let _ = writeln!(
                        s,
                        "\t\t\t<AngleBasisBlock><Theta>{}</Theta><nPhis>{}</nPhis><ThetaBounds><LowerTheta>{}</LowerTheta><UpperTheta>{}</UpperTheta></ThetaBounds></AngleBasisBlock>",
                        r.theta, r.nphis, r.lower, r.upper
                    );
                }
                s.push_str("\t\t</AngleBasis>\n");
            }
            s.push_str("\t</DataDefinition>\n");
            for c in &l.components {
                s.push_str("\t<WavelengthData>\n\t\t<LayerNumber>System</LayerNumber>\n");
                match &c.unit {
                    Some(u) => {
                        let _ = writeln!(
                            s,
                            "\t\t<Wavelength unit=\"{}\">{}</Wavelength>",
                            esc(u),
                            esc(c.channel.name())
                        );
                    }
                    None => {
                        let _ =
                            writeln!(s, "\t\t<Wavelength>{}</Wavelength>", esc(c.channel.name()));
                    }
                }
                if let Some(d) = &c.detector {
                    let _ = writeln!(s, "\t\t<DetectorSpectrum>{}</DetectorSpectrum>", esc(d));
                }
                let _ = writeln!(
                    s,
                    "\t\t<WavelengthDataBlock>\n\t\t\t<WavelengthDataDirection>{}</WavelengthDataDirection>",
                    c.direction.name()
                );
                match &c.data {
                    ScatteringData::Klems(k) => {
                        let _ = writeln!(
                            s,
                            "\t\t\t<ColumnAngleBasis>{}</ColumnAngleBasis>\n\t\t\t<RowAngleBasis>{}</RowAngleBasis>\n\t\t\t<ScatteringDataType>BTDF</ScatteringDataType>\n\t\t\t<ScatteringData>",
                            esc(&k.incident_basis),
                            esc(&k.outgoing_basis)
                        );
                        for row in k.values.chunks(k.n_in.max(1)) {
                            let line: Vec<String> = row.iter().map(|v| format!("{v}")).collect();
                            s.push_str(&line.join(" "));
                            s.push('\n');
                        }
                    }
                    ScatteringData::Tree(t) => {
                        let _ = writeln!(
                            s,
                            "\t\t\t<AngleBasis>{}</AngleBasis>\n\t\t\t<ScatteringDataType>BTDF</ScatteringDataType>\n\t\t\t<ScatteringData>",
                            esc(&t.basis)
                        );
                        write_tree(&mut s, &t.root);
                        s.push('\n');
                    }
                }
                s.push_str(
                    "\t\t\t</ScatteringData>\n\t\t</WavelengthDataBlock>\n\t</WavelengthData>\n",
                );
            }
            s.push_str("</Layer>\n");
        }
        s.push_str("</Optical>\n</WindowElement>\n");
        s
    }
}

fn write_tree(s: &mut String, n: &TreeNode) {
    // Iterative, as the reader bounds depth anyway, but a hand-built tree might not be.
    enum Step<'a> {
        Open(&'a TreeNode),
        Close,
    }
    let mut todo = vec![Step::Open(n)];
    while let Some(step) = todo.pop() {
        match step {
            Step::Close => s.push_str("}\n"),
            Step::Open(TreeNode::Leaf { values, .. }) => {
                s.push('{');
                let v: Vec<String> = values.iter().map(|v| format!("{v}")).collect();
                s.push_str(&v.join(" "));
                s.push_str("}\n");
            }
            Step::Open(TreeNode::Branch(kids)) => {
                s.push_str("{\n");
                todo.push(Step::Close);
                for k in kids.iter().rev() {
                    todo.push(Step::Open(k));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn klems_doc(structure: &str, data: &str) -> String {
        format!(
            r#"<?xml version="1.0"?>
<WindowElement>
<FileType>BSDF</FileType>
<Optical><Layer>
<Material><Name>Tiny</Name><Thickness unit="Millimeter">2</Thickness></Material>
<DataDefinition>
<IncidentDataStructure>{structure}</IncidentDataStructure>
<AngleBasis><AngleBasisName>Two</AngleBasisName>
<AngleBasisBlock><Theta>0</Theta><nPhis>1</nPhis><ThetaBounds><LowerTheta>0</LowerTheta><UpperTheta>45</UpperTheta></ThetaBounds></AngleBasisBlock>
<AngleBasisBlock><Theta>67.5</Theta><nPhis>2</nPhis><ThetaBounds><LowerTheta>45</LowerTheta><UpperTheta>90</UpperTheta></ThetaBounds></AngleBasisBlock>
</AngleBasis>
</DataDefinition>
<WavelengthData><Wavelength unit="Integral">Visible</Wavelength>
<WavelengthDataBlock><WavelengthDataDirection>Transmission Front</WavelengthDataDirection>
<ColumnAngleBasis>Two</ColumnAngleBasis><RowAngleBasis>Two</RowAngleBasis>
<ScatteringData>
{data}
</ScatteringData></WavelengthDataBlock></WavelengthData>
</Layer></Optical></WindowElement>
"#
        )
    }

    #[test]
    fn klems_columns_and_rows_agree_and_round_trip() {
        let c = parse(&klems_doc("Columns", "1, 2, 3\n4 5 6\n7,8,-9"), "c.xml").unwrap();
        let r = parse(&klems_doc("Rows", "1 4 7\n2 5 8\n3 6 -9"), "r.xml").unwrap();
        let (ScatteringData::Klems(kc), ScatteringData::Klems(kr)) = (
            &c.layers[0].components[0].data,
            &r.layers[0].components[0].data,
        ) else {
            panic!("not Klems")
        };
        assert_eq!(kc.values, kr.values);
        // Row = outgoing: value(out 0, in 1) is the first row's second number.
        assert_eq!(kc.value(0, 1), 2.0);
        assert_eq!(kc.value(2, 2), 0.0, "negatives clamp to 0");
        assert_eq!(c.layers[0].material.thickness, Some(0.002));
        assert_eq!(c.layers[0].components[0].channel, Channel::Visible);
        let back = parse(&c.to_xml(), "back.xml").unwrap();
        assert_eq!(
            back.layers[0].components[0].data,
            c.layers[0].components[0].data
        );
        assert_eq!(back.layers[0].bases, c.layers[0].bases);
        assert_eq!(back.layers[0].material, c.layers[0].material);
    }

    #[test]
    fn klems_errors_name_line_and_expectation() {
        let cases = [
            (
                klems_doc("Columns", "1 2 3 4 5 6 7 8"),
                "x.xml:16: expected 9 values",
            ),
            (
                klems_doc("Columns", "1 2 3 4 5 6 7 8 9 10"),
                "x.xml:17: expected 9 values in <ScatteringData>, found more",
            ),
            (
                klems_doc("Columns", "1 2 3\n4 x 6 7 8 9"),
                "x.xml:18: expected a number",
            ),
            (
                klems_doc("Diagonal", "1"),
                "x.xml:7: expected Columns, Rows",
            ),
            (
                klems_doc("Columns", "1").replace("<RowAngleBasis>Two", "<RowAngleBasis>Three"),
                "x.xml:15: expected <RowAngleBasis> to name",
            ),
            (
                klems_doc("Columns", "1").replace("<UpperTheta>90", "<UpperTheta>80"),
                "x.xml:8: expected angle basis 'Two' to end at 90",
            ),
        ];
        for (doc, want) in cases {
            let e = parse(&doc, "x.xml").unwrap_err().to_string();
            assert!(e.starts_with(want), "want {want}, got {e}");
        }
    }

    #[test]
    fn tensor_trees_parse_nested_and_reject_bad_counts() {
        let doc = |data: &str| {
            format!(
                "<WindowElement><Optical><Layer><DataDefinition><IncidentDataStructure>TensorTree3</IncidentDataStructure></DataDefinition>\n<WavelengthData><Wavelength>Visible</Wavelength><WavelengthDataBlock><WavelengthDataDirection>Reflection Back</WavelengthDataDirection><AngleBasis>LBNL/Shirley-Chiu</AngleBasis>\n<ScatteringData>{data}</ScatteringData></WavelengthDataBlock></WavelengthData></Layer></Optical></WindowElement>"
            )
        };
        let eight = "1 2 3 4 5 6 7 8";
        let nested = format!("{{ {{{eight}}}, {{1}} {{2}} {{3}} {{4}} {{5}} {{6}} {{7}} }}");
        let b = parse(&doc(&nested), "t.xml").unwrap();
        let ScatteringData::Tree(t) = &b.layers[0].components[0].data else {
            panic!()
        };
        let TreeNode::Branch(k) = &t.root else {
            panic!()
        };
        assert_eq!(k.len(), 8);
        assert_eq!(
            k[0],
            TreeNode::Leaf {
                log2: 1,
                values: (1..=8).map(|v| v as f32).collect()
            }
        );
        assert_eq!(
            k[7],
            TreeNode::Leaf {
                log2: 0,
                values: vec![7.0]
            }
        );
        let mut back = parse(&b.to_xml(), "b.xml").unwrap();
        back.layers[0].components[0].line = b.layers[0].components[0].line;
        assert_eq!(back, b);
        for (data, want) in [
            ("{1 2 3}", "t.xml:3: expected a leaf of 2^(3 k) values"),
            ("{1 2 3 4 5 6 7 8", "t.xml:3: expected '}'"),
            ("{1} junk", "t.xml:3: expected the end of <ScatteringData>"),
            ("{{1}}", "t.xml:3: expected '{'"),
            ("", "t.xml:3: expected tensor-tree data"),
        ] {
            let e = parse(&doc(data), "t.xml").unwrap_err().to_string();
            assert!(e.starts_with(want), "{data}: want {want}, got {e}");
        }
        let deep = format!("{}1{}", "{".repeat(40), "}".repeat(40));
        let e = parse(&doc(&deep), "t.xml").unwrap_err().to_string();
        assert!(e.contains("nested levels"), "{e}");
    }

    #[test]
    fn prefixes_never_panic() {
        let doc = klems_doc("Columns", "1 2 3 4 5 6 7 8 9");
        for i in (0..doc.len()).step_by(7) {
            let _ = parse(&doc[..i], "p.xml");
        }
    }
}
