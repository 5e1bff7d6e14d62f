//! Glare-source detection as evalglare 3.06's code does it (`main`, `find_near_pgs`,
//! `add_pixel_to_gs`, `find_split`, `split_pixel_from_gs`, `add_secondary_gs`,
//! `get_task_lum` in `src/util/evalglare.c`; notes in `docs/radiance-notes.md` §9.2).
//!
//! 1. Threshold: `-b f` with f > 100 is absolute (cd/m²); otherwise the threshold is
//!    f × the task luminance (`-t/-T x y r`: ω-weighted mean in the cone of `2·acos(d·dₜ) ≤
//!    r`), or × the picture's mean luminance without a task. Default 2000 cd/m² absolute;
//!    with a task and no `-b`, 5 × task luminance. (evalglare's man page, v2.10, still
//!    describes the old default "5 × average".)
//! 2. First scan (x outer, y inner, y from the bottom): a valid pixel brighter than the
//!    threshold joins the source found by `find_near_pgs` within `2·acos(d·d') ≤ r` (`-r`,
//!    default 0.2) among columns ≤ x, or starts a new source; while the previous pixel of
//!    the column was a source pixel its source is reused without a search (evalglare's
//!    speed-up, which shapes the result).
//! 3. Second scan, repeated until nothing changes: a source pixel next to a pixel of another
//!    number looks within r for a source with a larger solid angle than its own and the
//!    best found so far, and its whole source moves there.
//! 4. Smoothing (`-s`, off by default): pixels whose circle of `r/r_px/1.75` pixels holds
//!    more than 20 % (by ω) of primary pixels of a source join it.
//! 5. Peak extraction (`-y` default, `-x` off, `-Y L`; limit 50000 cd/m²): pixels ≥ limit
//!    leave their source for new ones grouped within r/2 (`find_split`), which are then
//!    merged like step 3 among themselves.
//!
//! Every source keeps ω-weighted mean luminance, Σω, pixel count, and the L·ω-weighted
//! centroid in (fractional) pixel coordinates, updated pixel by pixel exactly as evalglare's
//! running means do.

use super::pixels::Pixels;

/// One glare source.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Source {
    /// Pixels (evalglare keeps a double).
    pub npix: f64,
    /// L·ω-weighted centroid, x from the left (pixels).
    pub posx: f64,
    /// L·ω-weighted centroid, y from the **bottom** (pixels).
    pub posy: f64,
    /// ω-weighted mean luminance (cd/m²).
    pub lum: f64,
    /// Σω (sr).
    pub omega: f64,
    /// Smallest pixel luminance.
    pub lum_min: f64,
    /// Largest pixel luminance.
    pub lum_max: f64,
    /// Σ cos·ω·L of its pixels (lx).
    pub eglare: f64,
}

/// Detection settings (evalglare's options in brackets).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectOptions {
    /// Threshold value (`-b`); `None` = default (2000, or 5 with a task).
    pub threshold: Option<f64>,
    /// Search radius (rad) (`-r`).
    pub radius: f64,
    /// Peak extraction (`-y`/`-x`).
    pub peaks: bool,
    /// Peak extraction limit (cd/m²) (`-Y`).
    pub peak_limit: f64,
    /// Smoothing (`-s`).
    pub smooth: bool,
    /// Task area: x, y (evalglare pixel coordinates, y from the bottom), opening (rad).
    pub task: Option<(usize, usize, f64)>,
}

impl Default for DetectOptions {
    fn default() -> Self {
        DetectOptions {
            threshold: None,
            radius: 0.2,
            peaks: true,
            peak_limit: 50000.0,
            smooth: false,
            task: None,
        }
    }
}

/// How the threshold was obtained (reported on stderr).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Absolute luminance.
    Absolute,
    /// Multiple of the task luminance.
    TaskMultiple(f64),
    /// Multiple of the picture's mean luminance.
    MeanMultiple(f64),
}

/// The outcome of detection.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// Sources by evalglare's internal number (index 0 unused); empty ones (npix 0) were
    /// merged away.
    pub sources: Vec<Source>,
    /// Source number of every pixel (flat index), 0 = none.
    pub gsn: Vec<u32>,
    /// Luminance threshold used (cd/m²).
    pub threshold: f64,
    /// How it was obtained.
    pub method: Method,
    /// Task luminance (the mean luminance when no task is given).
    pub lum_task: f64,
    /// Search radius in pixels at the picture's centre.
    pub search_pix: f64,
    /// Warnings evalglare prints (search radius below 3 pixels).
    pub warnings: Vec<String>,
}

/// Pixels per side of a [`Tiles`] tile, and tiles per side of a block of tiles.
const TILE: usize = 16;
const BLOCK: usize = 8;
/// Slack (rad) on the cone tests of [`Tiles`]: far above the rounding of the dot products
/// and arc cosines involved (below 1e-7 rad), far below a pixel (1e-3 rad at 1000 pixels
/// over 180°), so it only costs an occasional needless exact check.
const CONE_SLACK: f64 = 1e-6;

/// Which sources can have a pixel within the search radius of a given direction, without
/// walking the radius: the picture cut into tiles of `TILE²` pixels, each with a cone
/// (axis, half-angle) holding the directions of its valid pixels and the numbers of the
/// sources that have (or had) pixels in it; blocks of `BLOCK²` tiles have cones holding
/// their tiles' cones. A tile can hold a pixel within angle `r/2` of direction `d` only if
/// `angle(d, axis) ≤ r/2 + half-angle`, so most of the picture is ruled out with a few
/// dot products. Only a "no" is used (see [`State::bigger_within`]); a "maybe" is settled
/// by evalglare's own walk.
struct Tiles {
    /// The search radius the thresholds are for.
    r: f64,
    /// Tiles across and down.
    nx: usize,
    ny: usize,
    /// Per tile: cone axis and the cosine threshold `cos(r/2 + half-angle + slack)`
    /// (−2 when the cone may reach any direction; +2 for a tile without valid pixels).
    axis: Vec<[f64; 3]>,
    thr: Vec<f64>,
    /// Per tile: source numbers that joined it (never removed: a superset).
    ids: Vec<Vec<usize>>,
    /// Per block of tiles (`BLOCK × BLOCK`): cone axis and threshold as for tiles.
    block_axis: Vec<[f64; 3]>,
    block_thr: Vec<f64>,
}

impl Tiles {
    /// Cones of `p`'s valid pixels for the search radius `r`, and the sources of `gsn`.
    fn new(p: &Pixels, gsn: &[u32], r: f64) -> Tiles {
        use super::pixels::dot;
        let (nx, ny) = (p.xres.div_ceil(TILE), p.yres.div_ceil(TILE));
        let ok = |x: usize, y: usize| {
            let i = p.at(x, y);
            p.inview[i] && p.valid[i]
        };
        let unit = |v: [f64; 3]| {
            let l = dot(v, v).sqrt();
            (l > 1e-9).then(|| [v[0] / l, v[1] / l, v[2] / l])
        };
        // the threshold for a cone of half-angle `beta`: its directions within r/2 of d need
        // dot(d, axis) >= cos(r/2 + beta)
        let thr_of = |beta: f64| {
            let a = 0.5 * r + beta + CONE_SLACK;
            if a >= std::f64::consts::PI {
                -2.0
            } else {
                a.cos()
            }
        };
        let angle = |a: [f64; 3], b: [f64; 3]| dot(a, b).clamp(-1.0, 1.0).acos();
        let mut t = Tiles {
            r,
            nx,
            ny,
            axis: vec![[0.0; 3]; nx * ny],
            thr: vec![2.0; nx * ny],
            ids: vec![Vec::new(); nx * ny],
            block_axis: Vec::new(),
            block_thr: Vec::new(),
        };
        let mut sum = vec![[0.0; 3]; nx * ny];
        let mut beta = vec![0.0; nx * ny];
        // tiles and their pixels column by column, the order of the pixel arrays
        for tx in 0..nx {
            for ty in 0..ny {
                let k = tx + ty * nx;
                let (xs, ys) = (
                    tx * TILE..((tx + 1) * TILE).min(p.xres),
                    ty * TILE..((ty + 1) * TILE).min(p.yres),
                );
                let mut s = [0.0; 3];
                for x in xs.clone() {
                    for y in ys.clone() {
                        if ok(x, y) {
                            let d = p.dir[p.at(x, y)];
                            s = [s[0] + d[0], s[1] + d[1], s[2] + d[2]];
                            let g = gsn[p.at(x, y)] as usize;
                            if g > 0 && !t.ids[k].contains(&g) {
                                t.ids[k].push(g);
                            }
                        }
                    }
                }
                sum[k] = s;
                let Some(axis) = unit(s) else {
                    // no valid pixel, or directions cancelling out (the cone test then
                    // lets everything through)
                    if s != [0.0; 3] {
                        t.thr[k] = -2.0;
                        beta[k] = std::f64::consts::PI;
                    }
                    continue;
                };
                let mut min_dot = 1.0f64;
                for x in xs.clone() {
                    for y in ys.clone() {
                        if ok(x, y) {
                            min_dot = min_dot.min(dot(axis, p.dir[p.at(x, y)]));
                        }
                    }
                }
                t.axis[k] = axis;
                beta[k] = min_dot.clamp(-1.0, 1.0).acos();
                t.thr[k] = thr_of(beta[k]);
            }
        }
        let (bx, by) = (nx.div_ceil(BLOCK), ny.div_ceil(BLOCK));
        for b in 0..bx * by {
            let (x0, y0) = ((b % bx) * BLOCK, (b / bx) * BLOCK);
            let tiles = || {
                (y0..(y0 + BLOCK).min(ny))
                    .flat_map(move |ty| (x0..(x0 + BLOCK).min(nx)).map(move |tx| tx + ty * nx))
            };
            let mut s = [0.0; 3];
            for k in tiles() {
                s = [s[0] + sum[k][0], s[1] + sum[k][1], s[2] + sum[k][2]];
            }
            let (axis, thr) = match unit(s) {
                Some(axis) => {
                    let mut beta_b = 0.0f64;
                    for k in tiles() {
                        if t.thr[k] <= 1.0 {
                            beta_b = beta_b.max(angle(axis, t.axis[k]) + beta[k] + CONE_SLACK);
                        }
                    }
                    (axis, thr_of(beta_b))
                }
                None if s == [0.0; 3] => ([0.0; 3], 2.0),
                None => ([0.0; 3], -2.0),
            };
            t.block_axis.push(axis);
            t.block_thr.push(thr);
        }
        t
    }

    /// Note that source `g` has a pixel at `(x, y)`.
    #[inline]
    fn add(&mut self, x: usize, y: usize, g: usize) {
        let ids = &mut self.ids[x / TILE + (y / TILE) * self.nx];
        if !ids.contains(&g) {
            ids.push(g);
        }
    }
}

struct State<'a> {
    p: &'a Pixels,
    /// Source number per pixel (0: none); `u32` halves the largest array of the detection.
    gsn: Vec<u32>,
    pgs: Vec<bool>,
    src: Vec<Source>,
    /// The cones of the merging searches, made at the first one.
    tiles: Option<Tiles>,
    /// Skip the merging walks and the peak-merging passes that cannot change anything
    /// (off only in a test).
    prune: bool,
    /// Merging walks run and skipped.
    walks: [usize; 2],
}

impl State<'_> {
    /// True when some pixel within `r` of `(x, y)` (anywhere in the picture, as
    /// [`Pixels::within_dirs`] decides) belongs to a source numbered in `ids` with a
    /// larger solid angle than `old`. When false, [`State::find_near`]'s merging walk
    /// cannot change anything (it only acts on such a pixel), so it is skipped: most
    /// pixels on a source's edge have no larger source in reach, and their walks over the
    /// whole search circle (thousands of pixels) were most of the detection's time.
    fn bigger_within(
        &mut self,
        (x, y): (usize, usize),
        r: f64,
        old: usize,
        ids: std::ops::RangeInclusive<usize>,
    ) -> bool {
        let p = self.p;
        if self.tiles.as_ref().is_none_or(|t| t.r != r) {
            self.tiles = Some(Tiles::new(p, &self.gsn, r));
        }
        let cos_half = (0.5 * r).cos();
        let t = self.tiles.as_ref().expect("made above");
        let here = p.dir[p.at(x, y)];
        let om = self.src[old].omega;
        let bigger = |f: usize| ids.contains(&f) && self.src[f].omega > om;
        let bx = t.nx.div_ceil(BLOCK);
        for b in 0..t.block_thr.len() {
            if super::pixels::dot(here, t.block_axis[b]) < t.block_thr[b] {
                continue;
            }
            let (x0, y0) = ((b % bx) * BLOCK, (b / bx) * BLOCK);
            for ty in y0..(y0 + BLOCK).min(t.ny) {
                for tx in x0..(x0 + BLOCK).min(t.nx) {
                    let k = tx + ty * t.nx;
                    if !t.ids[k].iter().any(|&f| bigger(f))
                        || super::pixels::dot(here, t.axis[k]) < t.thr[k]
                    {
                        continue;
                    }
                    for xx in tx * TILE..((tx + 1) * TILE).min(p.xres) {
                        for yy in ty * TILE..((ty + 1) * TILE).min(p.yres) {
                            let f = self.gsn[p.at(xx, yy)] as usize;
                            if f > 0
                                && bigger(f)
                                && Pixels::within_dirs(here, p.dir[p.at(xx, yy)], r, cos_half)
                            {
                                return true;
                            }
                        }
                    }
                }
            }
        }
        false
    }

    fn new_source(&mut self) -> usize {
        self.src.push(Source {
            lum_min: f64::INFINITY,
            ..Source::default()
        });
        self.src.len() - 1
    }

    /// `add_pixel_to_gs`.
    fn add_pixel(&mut self, x: usize, y: usize, g: usize) {
        let i = self.p.at(x, y);
        let (om, l) = (self.p.omega[i], self.p.lum[i]);
        let s = &mut self.src[g];
        s.npix += 1.0;
        let (opx, opy, ol, oo) = (s.posx, s.posy, s.lum, s.omega);
        let no = oo + om;
        s.lum = (ol * oo + l * om) / no;
        s.posx = (opx * oo * ol + x as f64 * om * l) / (ol * oo + l * om);
        s.posy = (opy * oo * ol + y as f64 * om * l) / (ol * oo + l * om);
        s.omega = no;
        if l < s.lum_min {
            s.lum_min = l;
        }
        if l > s.lum_max {
            s.lum_max = l;
        }
        self.gsn[i] = g as u32;
        if let Some(t) = self.tiles.as_mut() {
            t.add(x, y, g);
        }
    }

    /// `split_pixel_from_gs`: move pixel to source `g`.
    fn split_pixel(&mut self, x: usize, y: usize, g: usize) {
        let i = self.p.at(x, y);
        let (om, l) = (self.p.omega[i], self.p.lum[i]);
        let s = &mut self.src[self.gsn[i] as usize];
        s.npix -= 1.0;
        let (opx, opy, oo, ol) = (s.posx, s.posy, s.omega, s.lum);
        let no = oo - om;
        s.omega = no;
        s.lum = (ol * oo - l * om) / no;
        s.posx = (opx * ol * oo - x as f64 * l * om) / (ol * oo - l * om);
        s.posy = (opy * ol * oo - y as f64 * l * om) / (ol * oo - l * om);
        self.add_pixel(x, y, g);
    }

    /// `find_near_pgs`: with `act == 0` (first scan) the number of a source pixel within
    /// `r` among columns ≤ x (0 if none); otherwise merge the pixel's source into a larger
    /// one within `r` numbered in `min..=max`, returning the pixel's (new) number.
    fn find_near(
        &mut self,
        x: usize,
        y: usize,
        r: f64,
        act: usize,
        max: usize,
        min: usize,
    ) -> usize {
        let p = self.p;
        let (x, y) = (x as i64, y as i64);
        let cos_half = (0.5 * r).cos();

        let x_max = if act == 0 { x } else { p.xres as i64 - 1 };
        let y_max = p.yres as i64 - 1;
        let here = p.at(x as usize, y as usize);
        let old = self.gsn[here] as usize;
        if act > 0 {
            if self.prune && !self.bigger_within((x as usize, y as usize), r, old, min..=max) {
                self.walks[1] += 1;
                return old;
            }
            self.walks[0] += 1;
        }
        let mut new = old;
        let mut change = false;
        let mut near = if act > 0 { old } else { 0 };
        for dy in [-1i64, 1] {
            let mut iy = if dy == -1 { y } else { y + 1 };
            let mut ixm = [x, x];
            let mut stop_y = false;
            while iy <= y_max && iy >= 0 && !stop_y {
                for (k, dx) in [-1i64, 1].into_iter().enumerate() {
                    let mut ix = (ixm[0] + ixm[1]) / 2;
                    let mut stop_x = false;
                    while ix <= x_max && ix >= 0 && !stop_x && !stop_y {
                        let j = p.at(ix as usize, iy as usize);
                        if Pixels::within_dirs(p.dir[here], p.dir[j], r, cos_half) {
                            let f = self.gsn[j] as usize;
                            if f > 0 {
                                if act == 0 {
                                    near = f;
                                    stop_x = true;
                                    stop_y = true;
                                } else if self.src[old].omega < self.src[f].omega
                                    && self.src[f].omega > self.src[new].omega
                                    && f >= min
                                    && f <= max
                                {
                                    new = f;
                                    change = true;
                                    stop_x = true;
                                    stop_y = true;
                                }
                            }
                        } else {
                            ixm[k] = ix - dx;
                            stop_x = true;
                        }
                        ix += dx;
                    }
                }
                iy += dy;
            }
        }
        if change {
            let s = &mut self.src[old];
            s.lum = 0.0;
            s.omega = 0.0;
            s.npix = 0.0;
            s.lum_max = 0.0;
            near = new;
            for xx in 0..p.xres {
                for yy in 0..p.yres {
                    if self.gsn[p.at(xx, yy)] as usize == old {
                        self.add_pixel(xx, yy, new);
                    }
                }
            }
        }
        near
    }

    /// `find_split`: a source numbered in `start..=end` within `r` of the pixel, 0 if none
    /// (the last one met in evalglare's walk). evalglare bounds x by the picture's *height*;
    /// we bound it by the smaller of width and height (the same for square pictures, and
    /// never outside the picture).
    fn find_split(&self, x: usize, y: usize, r: f64, start: usize, end: usize) -> usize {
        let cos_half = (0.5 * r).cos();
        let p = self.p;
        let here = p.at(x, y);
        let (x, y) = (x as i64, y as i64);
        let x_max = p.yres.min(p.xres) as i64 - 1;
        let y_max = p.yres as i64 - 1;
        let mut found = 0;
        for dy in [-1i64, 1] {
            let mut iy = if dy == -1 { y } else { y + 1 };
            while iy <= y_max && iy >= 0 {
                let mut out_r = false;
                for dx in [-1i64, 1] {
                    let mut ix = if dx == -1 { x } else { x + 1 };
                    while ix <= x_max && ix >= 0 {
                        let j = p.at(ix as usize, iy as usize);
                        if Pixels::within_dirs(p.dir[here], p.dir[j], r, cos_half) {
                            out_r = true;
                            let g = self.gsn[j] as usize;
                            if g >= start && g <= end {
                                found = g;
                            }
                            ix += dx;
                        } else {
                            break;
                        }
                    }
                }
                if !out_r {
                    break;
                }
                iy += dy;
            }
        }
        found
    }

    /// `add_secondary_gs` (smoothing).
    fn add_secondary(&mut self, x: usize, y: usize, r: f64, g: usize) {
        let p = self.p;
        let (xi, yi) = (x as i64, y as i64);
        // evalglare truncates x ± r to int and clips the upper ends to size − 2
        let clip = |v: f64, n: usize| -> i64 {
            let v = v as i64;
            if v > n as i64 - 1 { n as i64 - 2 } else { v }
        };
        let x_min = ((x as f64 - r) as i64).max(0);
        let x_max = clip(x as f64 + r, p.xres);
        let y_min = ((y as f64 - r) as i64).max(0);
        let y_max = clip(y as f64 + r, p.yres);
        let (mut om_gs, mut om_tot) = (0.0, 0.0);
        for ix in x_min..=x_max {
            for iy in y_min..=y_max {
                // integer arithmetic inside sqrt, as evalglare
                let d = (((xi - ix) * (xi - ix) + (yi - iy) * (yi - iy)) as f64).sqrt();
                if d <= r {
                    let j = p.at(ix as usize, iy as usize);
                    om_tot += p.omega[j];
                    if self.gsn[j] as usize == g && self.pgs[j] {
                        om_gs += p.omega[j];
                    }
                }
            }
        }
        if om_gs / om_tot > 0.2 {
            self.add_pixel(x, y, g);
        }
    }
}

/// `get_task_lum`: ω-weighted mean luminance within `2·acos(d·dₜ) ≤ r` of pixel (x, y),
/// over every pixel of the picture (evalglare does not check validity here).
pub fn task_luminance(p: &Pixels, x: usize, y: usize, r: f64) -> f64 {
    let c = p.at(x, y);
    let cos_half = (0.5 * r).cos();
    let (mut s, mut o) = (0.0, 0.0);
    for xx in 0..p.xres {
        for yy in 0..p.yres {
            let j = p.at(xx, yy);
            if p.within(c, j, r, cos_half) {
                s += p.omega[j] * p.lum[j];
                o += p.omega[j];
            }
        }
    }
    s / o
}

/// Radius (rad) per pixel at the picture's centre as evalglare estimates it: a tenth of the
/// `2·acos` distance from pixel (w/2, h/2) to (w/2 + 10, h/2 + 10).
fn centre_radius(p: &Pixels) -> f64 {
    let (cx, cy) = (p.xres / 2, p.yres / 2);
    let (rx, ry) = ((cx + 10).min(p.xres - 1), (cy + 10).min(p.yres - 1));
    p.radius(p.at(cx, cy), p.at(rx, ry)) / 10.0
}

/// Detect glare sources. `avlum` is the picture's ω-weighted mean luminance over valid
/// pixels (the threshold's reference without a task).
pub fn detect(p: &Pixels, opts: &DetectOptions, avlum: f64) -> Detection {
    detect_with(p, opts, avlum, true).0
}

/// [`detect`], with or without its shortcuts ([`State::bigger_within`], the peak merging
/// confined to the moved pixels); also returns how many merging walks ran and how many
/// were skipped.
fn detect_with(
    p: &Pixels,
    opts: &DetectOptions,
    avlum: f64,
    prune: bool,
) -> (Detection, [usize; 2]) {
    let mut warnings = Vec::new();
    let r = opts.radius;
    let search_pix = r / centre_radius(p);
    let (mut peaks, mut smooth) = (opts.peaks, opts.smooth);
    if search_pix < 1.0 {
        warnings.push(
            "search radius less than 1 pixel: smoothing and peak extraction deactivated".into(),
        );
        peaks = false;
        smooth = false;
    } else if search_pix < 3.0 {
        warnings.push(format!(
            "search radius less than 3 pixels ({search_pix:.6})"
        ));
    }
    let lum_task = match opts.task {
        Some((x, y, rt)) => task_luminance(p, x, y, rt),
        None => avlum,
    };
    let factor = opts
        .threshold
        .unwrap_or(if opts.task.is_some() { 5.0 } else { 2000.0 });
    let (threshold, method) = if factor > 100.0 {
        (factor, Method::Absolute)
    } else if opts.task.is_some() {
        (factor * lum_task, Method::TaskMultiple(factor))
    } else {
        (factor * lum_task, Method::MeanMultiple(factor))
    };

    let n = p.xres * p.yres;
    let mut st = State {
        p,
        gsn: vec![0; n],
        pgs: vec![false; n],
        src: vec![Source::default()],
        tiles: None,
        prune,
        walks: [0, 0],
    };
    let ok = |i: usize| p.inview[i] && p.valid[i];

    // first scan
    let mut lum_total_max: f64 = 0.0;
    let mut actual = 0;
    for x in 0..p.xres {
        let mut last = 0;
        for y in 0..p.yres {
            let i = p.at(x, y);
            if !ok(i) {
                continue;
            }
            let l = p.lum[i];
            if l > threshold {
                lum_total_max = lum_total_max.max(l);
                if last == 0 || search_pix <= 1.0 {
                    let igs = st.src.len() - 1;
                    actual = st.find_near(x, y, r, 0, igs, 1);
                }
                if actual == 0 {
                    actual = st.new_source();
                }
                st.gsn[i] = actual as u32;
                st.pgs[i] = true;
                st.add_pixel(x, y, actual);
                last = actual;
            } else {
                st.pgs[i] = false;
                last = 0;
            }
        }
    }

    // second scan: merge neighbours into larger sources until stable
    if search_pix > 1.0 {
        let mut change = true;
        while change {
            change = false;
            for x in 0..p.xres {
                for y in 0..p.yres {
                    let i = p.at(x, y);
                    if !p.inview[i] {
                        continue;
                    }
                    let before = st.gsn[i] as usize;
                    if before == 0 || !p.valid[i] {
                        continue;
                    }
                    if x > 1 && x + 2 < p.xres && y > 1 && y + 2 < p.yres {
                        let same = [
                            (-1i64, 0i64),
                            (1, 0),
                            (0, -1),
                            (0, 1),
                            (-1, -1),
                            (1, -1),
                            (-1, 1),
                            (1, 1),
                        ]
                        .iter()
                        .all(|&(dx, dy)| {
                            st.gsn[p.at((x as i64 + dx) as usize, (y as i64 + dy) as usize)]
                                as usize
                                == before
                        });
                        if same {
                            continue;
                        }
                    }
                    let igs = st.src.len() - 1;
                    if st.find_near(x, y, r, before, igs, 1) != before {
                        change = true;
                    }
                }
            }
        }
    }

    // smoothing
    let i_max = st.src.len() - 1;
    if smooth {
        let sp = r / centre_radius(p) / 1.75;
        for x in 0..p.xres {
            for y in 0..p.yres {
                let i = p.at(x, y);
                if p.inview[i] && p.valid[i] && st.gsn[i] == 0 {
                    for g in 1..=i_max {
                        if st.src[g].npix > 0.0 {
                            st.add_secondary(x, y, sp, g);
                        }
                    }
                }
            }
        }
    }

    // peak extraction
    if peaks && lum_total_max > opts.peak_limit {
        let limit = opts.peak_limit;
        let r_split = r / 2.0;
        for g in 0..=i_max {
            if st.src[g].npix <= 0.0 {
                continue;
            }
            let start = st.src.len();
            // the pixels moved to the new sources (numbered from `start`): their box
            let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (usize::MAX, 0, usize::MAX, 0);
            if st.src[g].lum_max >= limit {
                for x in 0..p.xres {
                    for y in 0..p.yres {
                        let i = p.at(x, y);
                        if ok(i) && p.lum[i] >= limit && st.gsn[i] as usize == g {
                            (x_lo, x_hi) = (x_lo.min(x), x_hi.max(x));
                            (y_lo, y_hi) = (y_lo.min(y), y_hi.max(y));
                            let mut split = if st.src.len() == start {
                                st.new_source()
                            } else {
                                st.find_split(x, y, r_split, start, st.src.len() - 1)
                            };
                            if split == 0 {
                                split = st.new_source();
                            }
                            st.split_pixel(x, y, split);
                        }
                    }
                }
            }
            // Merge the new sources among themselves. Only pixels numbered from `start`
            // act, and merging only renumbers them among those sources, so evalglare's
            // passes over the whole picture come down to the box of the moved pixels (in
            // the same order), and to nothing when no pixel moved.
            if !st.prune {
                // the whole picture, as evalglare (the test of the shortcuts)
                (x_lo, x_hi, y_lo, y_hi) = (0, p.xres - 1, 0, p.yres - 1);
            }
            let mut change = st.src.len() > start || !st.prune;
            while change {
                change = false;
                for x in x_lo..=x_hi {
                    for y in y_lo..=y_hi {
                        let i = p.at(x, y);
                        let before = st.gsn[i] as usize;
                        if before >= start && before > 0 && ok(i) {
                            let igs = st.src.len() - 1;
                            if st.find_near(x, y, r, before, igs, start) != before {
                                change = true;
                            }
                        }
                    }
                }
            }
        }
    }

    // direct illuminance of each source
    for i in 0..n {
        let g = st.gsn[i] as usize;
        if g > 0 && ok(i) {
            let d = super::pixels::dot(p.camera.dir(), p.dir[i]) * p.omega[i] * p.lum[i];
            st.src[g].eglare += d;
        }
    }

    let walks = st.walks;
    let det = Detection {
        sources: st.src,
        gsn: st.gsn,
        threshold,
        method,
        lum_task,
        search_pix,
        warnings,
    };
    (det, walks)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::picture::{Picture, PixelFormat};
    use crate::formats::view::View;
    use crate::radiometry::Channels;

    /// A 180° angular fisheye of `n²` pixels: a dim background with bright patches of
    /// random sizes and places (some near each other, so they merge; some above the peak
    /// limit, so they split), from a seeded generator.
    fn spotted(n: usize, seed: u64) -> Pixels {
        let mut state = seed;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pic = Picture::new(n, n, Channels::rgb(), PixelFormat::Rgbe);
        let mut lum = vec![1.0f64; n * n];
        for _ in 0..12 {
            let (cx, cy) = (next() * n as f64, next() * n as f64);
            let (w, h) = (1.0 + next() * n as f64 / 8.0, 1.0 + next() * n as f64 / 8.0);
            let l = if next() < 0.3 {
                80000.0
            } else {
                3000.0 + next() * 20000.0
            };
            for y in 0..n {
                for x in 0..n {
                    if (x as f64 - cx).abs() < w && (y as f64 - cy).abs() < h {
                        lum[x + y * n] = l * (0.9 + 0.2 * next());
                    }
                }
            }
        }
        for (k, l) in lum.iter().enumerate() {
            // grey pixels: R = G = B = L / 179
            let v = (*l / 179.0) as f32;
            pic.data[3 * k..3 * k + 3].copy_from_slice(&[v, v, v]);
        }
        let mut view = View::default();
        for a in [
            &["-vta"][..],
            &["-vh", "180"],
            &["-vv", "180"],
            &["-vd", "0", "-1", "0"],
        ] {
            view.apply_arg(a).unwrap();
        }
        Pixels::new(&pic, view.setup().unwrap())
    }

    /// Skipping the merging walks that [`State::bigger_within`] rules out, and the peak
    /// merging outside the moved pixels, leaves every source and every pixel's source
    /// number as evalglare's full walks and passes make them, on pictures where sources do
    /// merge and split and walks are skipped.
    #[test]
    fn skipped_walks_change_nothing() {
        let (mut merged, mut skipped, mut ran) = (0, 0, 0);
        for seed in 1..=6 {
            let p = spotted(150, seed);
            for radius in [0.1, 0.2, 0.5] {
                let opts = DetectOptions {
                    radius,
                    ..DetectOptions::default()
                };
                let (full, w_full) = detect_with(&p, &opts, 10.0, false);
                let (fast, w_fast) = detect_with(&p, &opts, 10.0, true);
                assert_eq!(fast, full, "seed {seed}, radius {radius}");
                assert_eq!(
                    w_fast[0] + w_fast[1],
                    w_full[0],
                    "seed {seed}, radius {radius}"
                );
                merged += full
                    .sources
                    .iter()
                    .skip(1)
                    .filter(|s| s.npix == 0.0)
                    .count();
                skipped += w_fast[1];
                ran += w_fast[0];
            }
        }
        // not vacuous: sources merged, walks were both skipped and run
        assert!(
            merged > 10 && skipped > 1000 && ran > 10,
            "{merged} {skipped} {ran}"
        );
    }
}
