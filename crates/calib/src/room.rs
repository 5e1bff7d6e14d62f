//! # What the effects need to know about the model: windows and surface classes
//!
//! Windows are the surfaces whose material is `glass` (polygons). For each one the outward
//! normal (horizontal part, pointing away from the sensors), sill and head heights and area
//! are kept: the overhang effect uses them (profile angles, Chapter "shading" of any daylight
//! text, e.g. Tregenza & Wilson, *Daylighting*, 2011, sec. 10.2), the report uses the
//! distance of each sensor from the window wall.
//!
//! Reflectance classes group the opaque materials (`plastic`, `metal`, `trans`) the
//! reflectance effects scale: by a `--classes` mapping `material=class,...` first, else by
//! keywords in the material name (`wall`, `ceil`, `floor`, `ground`/`terrain`/`exterior`).

use crate::error::{Error, Result};
use crate::scene::{Primitive, Scene};

/// Surface classes whose reflectance the `reflectance` effects scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SurfaceClass {
    Walls,
    Ceiling,
    Floor,
    /// Exterior ground (and the gendaymtx ground patch): the ground-albedo effect.
    Ground,
}

impl SurfaceClass {
    pub const ALL: [SurfaceClass; 4] = [
        SurfaceClass::Walls,
        SurfaceClass::Ceiling,
        SurfaceClass::Floor,
        SurfaceClass::Ground,
    ];
    pub fn name(self) -> &'static str {
        match self {
            SurfaceClass::Walls => "walls",
            SurfaceClass::Ceiling => "ceiling",
            SurfaceClass::Floor => "floor",
            SurfaceClass::Ground => "ground",
        }
    }
    pub fn from_name(s: &str) -> Option<SurfaceClass> {
        SurfaceClass::ALL.into_iter().find(|c| c.name() == s)
    }
    /// Class by keyword in a material name.
    pub fn from_keyword(material: &str) -> Option<SurfaceClass> {
        let m = material.to_ascii_lowercase();
        if m.contains("wall") {
            Some(SurfaceClass::Walls)
        } else if m.contains("ceil") {
            Some(SurfaceClass::Ceiling)
        } else if m.contains("floor") {
            Some(SurfaceClass::Floor)
        } else if m.contains("ground") || m.contains("terrain") || m.contains("exterior") {
            Some(SurfaceClass::Ground)
        } else {
            None
        }
    }
}

/// Parse a `--classes` mapping `material=class,material=class`.
pub fn parse_classes(spec: &str) -> Result<Vec<(String, SurfaceClass)>> {
    let mut out = Vec::new();
    for item in spec.split(',').filter(|s| !s.trim().is_empty()) {
        let (m, c) = item.split_once('=').ok_or_else(|| {
            Error::Usage(format!(
                "--classes '{item}': expected material=class (walls, ceiling, floor, ground)"
            ))
        })?;
        let class = SurfaceClass::from_name(c.trim()).ok_or_else(|| {
            Error::Usage(format!(
                "--classes '{item}': unknown class '{c}'; expected walls, ceiling, floor or ground"
            ))
        })?;
        out.push((m.trim().to_string(), class));
    }
    Ok(out)
}

/// One glazed opening.
#[derive(Debug, Clone, PartialEq)]
pub struct Window {
    pub id: String,
    pub centroid: [f64; 3],
    /// Unit horizontal normal pointing outside (away from the sensors).
    pub outward: [f64; 3],
    pub sill: f64,
    pub head: f64,
    pub area: f64,
    /// Horizontal extent along the wall: (min, max) of the coordinate along `tangent`.
    pub span: (f64, f64),
    /// Unit horizontal direction along the wall (outward rotated 90 degrees).
    pub tangent: [f64; 3],
}

impl Window {
    /// Signed distance of `p` from the window plane, positive inside the room.
    pub fn depth_of(&self, p: [f64; 3]) -> f64 {
        -dot(sub(p, self.centroid), self.outward)
    }
    pub fn height(&self) -> f64 {
        self.head - self.sill
    }
}

/// Centroid of sensor positions (a point inside the room).
pub fn sensor_centroid(sensors: &[crate::formats::sensors::Sensor]) -> [f64; 3] {
    let n = sensors.len().max(1) as f64;
    sensors.iter().fold([0.0; 3], |c, s| {
        let o = s.ray.org;
        [c[0] + o[0] / n, c[1] + o[1] / n, c[2] + o[2] / n]
    })
}

pub(crate) use rdaylight_base::vec3::{dot, sub};

/// The model's windows and reflectance classes.
#[derive(Debug, Clone, PartialEq)]
pub struct Room {
    pub windows: Vec<Window>,
    /// The floor's outline in plan, (x0, y0, x1, y1) per edge: the boundary edges of the
    /// polygons of the floor class (or, without one, of the lowest horizontal polygons under
    /// the sensors), for the reports' plans.
    pub outline: Vec<[f64; 4]>,
    /// (material id, class) of every classified opaque material.
    pub materials: Vec<(String, SurfaceClass)>,
    /// Mean transmissivity and refractive index of the windows' glass (0.96, 1.52 if none).
    pub glass_tn: f64,
    pub glass_index: f64,
    /// Height of the floor (the lowest of the polygons of [`Room::outline`]; 0 without
    /// one): where added furniture stands.
    pub floor: f64,
    /// Mean diffuse reflectance of the ground-class materials (0 without an exterior
    /// ground): the share of a sky patch's light that reaches the windows off the ground,
    /// which an overhang does not block.
    pub ground_reflectance: f64,
    /// The polygons of the exterior ground (ground-class materials): where a ray leaving a
    /// window downwards meets the modelled ground rather than the sky's ground glow beyond
    /// it, which a near exterior obstruction hides.
    pub ground_polygons: Vec<Vec<[f64; 3]>>,
    /// Every other polygon that is not glass (the room's walls, ceiling, floor and
    /// furniture): where light entering a window first lands ([`Room::landing`]).
    pub opaque_polygons: Vec<Vec<[f64; 3]>>,
}

impl Room {
    /// Find windows (glass polygons) and classify materials. `inside` is a point in the room
    /// (the sensors' centroid) that decides which way is out.
    pub fn new(scene: &Scene, inside: [f64; 3], mapping: &[(String, SurfaceClass)]) -> Room {
        let mut windows = Vec::new();
        let (mut glass_tn, mut glass_index) = (0.96, 1.52);
        for (i, obj) in scene.surfaces() {
            let Primitive::Polygon { vertices } = &obj.kind else {
                continue;
            };
            let is_glass = scene
                .material_of(i)
                .is_some_and(|m| matches!(scene.objects[m].kind, Primitive::Glass { .. }));
            if !is_glass || vertices.len() < 3 {
                continue;
            }
            if let Some(Primitive::Glass {
                transmissivity,
                index,
            }) = scene.material_of(i).map(|m| &scene.objects[m].kind)
            {
                glass_tn = transmissivity.iter().sum::<f64>() / transmissivity.len().max(1) as f64;
                glass_index = index.unwrap_or(1.52);
            }
            let n = newell(vertices);
            let mut c = [0.0; 3];
            for a in vertices {
                for j in 0..3 {
                    c[j] += a[j] / vertices.len() as f64;
                }
            }
            let area = 0.5 * dot(n, n).sqrt();
            let h = (n[0] * n[0] + n[1] * n[1]).sqrt();
            if h < 1e-9 {
                continue; // skylights: not handled by the overhang geometry
            }
            let mut out = [n[0] / h, n[1] / h, 0.0];
            if dot(sub(c, inside), out) < 0.0 {
                out = [-out[0], -out[1], 0.0];
            }
            let tangent = [-out[1], out[0], 0.0];
            let zs = vertices.iter().map(|v| v[2]);
            let sill = zs.clone().fold(f64::INFINITY, f64::min);
            let head = zs.fold(f64::NEG_INFINITY, f64::max);
            let ts: Vec<f64> = vertices.iter().map(|v| dot(*v, tangent)).collect();
            let span = (
                ts.iter().copied().fold(f64::INFINITY, f64::min),
                ts.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            );
            windows.push(Window {
                id: obj.id.clone(),
                centroid: c,
                outward: out,
                sill,
                head,
                area,
                span,
                tangent,
            });
        }
        let mut materials = Vec::new();
        // Only materials some surface uses: a class whose materials cover nothing (a
        // `ground_mat` defined in a model without an exterior ground) has no effect to fit.
        let used: std::collections::HashSet<usize> = scene
            .objects
            .iter()
            .filter(|o| o.kind.is_surface())
            .filter_map(|o| o.modifier)
            .collect();
        for (i, o) in scene.objects.iter().enumerate() {
            if !used.contains(&i) {
                continue;
            }
            if !matches!(
                o.kind,
                Primitive::Plastic { .. } | Primitive::Metal { .. } | Primitive::Trans { .. }
            ) {
                continue;
            }
            let class = mapping
                .iter()
                .find(|(m, _)| *m == o.id)
                .map(|(_, c)| *c)
                .or_else(|| SurfaceClass::from_keyword(&o.id));
            if let Some(c) = class {
                if !materials.iter().any(|(m, _): &(String, _)| *m == o.id) {
                    materials.push((o.id.clone(), c));
                }
            }
        }
        let (outline, floor) = floor_outline(scene, inside, &materials);
        let grounds: Vec<f64> = scene
            .objects
            .iter()
            .filter(|o| {
                materials
                    .iter()
                    .any(|(id, c)| *c == SurfaceClass::Ground && *id == o.id)
            })
            .filter_map(|o| match &o.kind {
                Primitive::Plastic { color, .. } | Primitive::Metal { color, .. } => {
                    Some(color.iter().sum::<f64>() / color.len().max(1) as f64)
                }
                _ => None,
            })
            .collect();
        let ground_reflectance = if grounds.is_empty() {
            0.0
        } else {
            grounds.iter().sum::<f64>() / grounds.len() as f64
        };
        let ground_polygons = scene
            .surfaces()
            .filter(|(i, _)| {
                scene.material_of(*i).is_some_and(|m| {
                    materials
                        .iter()
                        .any(|(id, c)| *c == SurfaceClass::Ground && *id == scene.objects[m].id)
                })
            })
            .filter_map(|(_, o)| match &o.kind {
                Primitive::Polygon { vertices } if vertices.len() >= 3 => Some(vertices.clone()),
                _ => None,
            })
            .collect();
        let opaque_polygons = scene
            .surfaces()
            .filter(|(i, _)| {
                scene.material_of(*i).is_some_and(|m| {
                    let o = &scene.objects[m];
                    !matches!(o.kind, Primitive::Glass { .. })
                        && !materials
                            .iter()
                            .any(|(id, c)| *c == SurfaceClass::Ground && *id == o.id)
                })
            })
            .filter_map(|(_, o)| match &o.kind {
                Primitive::Polygon { vertices } if vertices.len() >= 3 => Some(vertices.clone()),
                _ => None,
            })
            .collect();
        Room {
            windows,
            outline,
            materials,
            glass_tn,
            glass_index,
            floor,
            ground_reflectance,
            ground_polygons,
            opaque_polygons,
        }
    }

    /// Whether the ray from `org` along `d` meets one of the [`Room::ground_polygons`].
    pub fn meets_ground(&self, org: [f64; 3], d: [f64; 3]) -> bool {
        self.ground_polygons
            .iter()
            .any(|v| polygon_hit(v, org, d).is_some())
    }

    /// Where the ray from `org` along `d` first meets one of the [`Room::ground_polygons`].
    pub fn ground_hit(&self, org: [f64; 3], d: [f64; 3]) -> Option<[f64; 3]> {
        let t = self
            .ground_polygons
            .iter()
            .filter_map(|v| polygon_hit(v, org, d))
            .fold(f64::INFINITY, f64::min);
        t.is_finite()
            .then(|| [org[0] + t * d[0], org[1] + t * d[1], org[2] + t * d[2]])
    }

    /// Where the ray from `org` along `d` first meets one of the
    /// [`Room::opaque_polygons`]: the point and the polygon's unit normal turned towards
    /// `org`.
    pub fn landing(&self, org: [f64; 3], d: [f64; 3]) -> Option<([f64; 3], [f64; 3])> {
        let (t, v) = self
            .opaque_polygons
            .iter()
            .filter_map(|v| polygon_hit(v, org, d).map(|t| (t, v)))
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        let mut n = newell(v);
        let len = dot(n, n).sqrt();
        if len < 1e-12 {
            return None;
        }
        let s = if dot(n, d) > 0.0 { -1.0 } else { 1.0 } / len;
        n = [n[0] * s, n[1] * s, n[2] * s];
        Some(([org[0] + t * d[0], org[1] + t * d[1], org[2] + t * d[2]], n))
    }

    /// Classes that have at least one material.
    pub fn classes(&self) -> Vec<SurfaceClass> {
        let mut c: Vec<SurfaceClass> = self.materials.iter().map(|m| m.1).collect();
        c.sort();
        c.dedup();
        c
    }

    /// Distance of `p` from the nearest window wall (metres into the room).
    pub fn depth(&self, p: [f64; 3]) -> f64 {
        self.windows
            .iter()
            .map(|w| w.depth_of(p).abs())
            .fold(f64::INFINITY, f64::min)
    }
}

/// The plan outline of the floor: edges used by exactly one floor polygon (edges shared by
/// two pieces of a tiled floor are inside it). Floor polygons are those whose material is of
/// the floor class; a model without one falls back to the horizontal polygons at the lowest
/// height below `inside` whose plan bounds contain it.
fn floor_outline(
    scene: &Scene,
    inside: [f64; 3],
    materials: &[(String, SurfaceClass)],
) -> (Vec<[f64; 4]>, f64) {
    let polys: Vec<&Vec<[f64; 3]>> = scene
        .surfaces()
        .filter_map(|(i, o)| match &o.kind {
            Primitive::Polygon { vertices } if vertices.len() >= 3 => Some((i, vertices)),
            _ => None,
        })
        .filter(|(_, v)| {
            let z0 = v[0][2];
            v.iter().all(|p| (p[2] - z0).abs() < 1e-3)
        })
        .filter(|(i, _)| {
            scene.material_of(*i).is_some_and(|m| {
                materials
                    .iter()
                    .any(|(id, c)| *c == SurfaceClass::Floor && *id == scene.objects[m].id)
            })
        })
        .map(|(_, v)| v)
        .collect();
    let polys = if polys.is_empty() {
        let flat: Vec<&Vec<[f64; 3]>> = scene
            .surfaces()
            .filter_map(|(_, o)| match &o.kind {
                Primitive::Polygon { vertices } if vertices.len() >= 3 => Some(vertices),
                _ => None,
            })
            .filter(|v| {
                let z0 = v[0][2];
                z0 < inside[2]
                    && v.iter().all(|p| (p[2] - z0).abs() < 1e-3)
                    && v.iter().any(|p| p[0] <= inside[0])
                    && v.iter().any(|p| p[0] >= inside[0])
                    && v.iter().any(|p| p[1] <= inside[1])
                    && v.iter().any(|p| p[1] >= inside[1])
            })
            .collect();
        let low = flat.iter().map(|v| v[0][2]).fold(f64::INFINITY, f64::min);
        flat.into_iter()
            .filter(|v| (v[0][2] - low).abs() < 0.01)
            .collect()
    } else {
        polys
    };
    let floor = polys.iter().map(|v| v[0][2]).fold(f64::INFINITY, f64::min);
    let floor = if floor.is_finite() { floor } else { 0.0 };
    // Edges keyed by their end points to the millimetre, either direction.
    type Point = (i64, i64);
    let key = |a: [f64; 3]| -> Point {
        (
            (a[0] * 1000.0).round() as i64,
            (a[1] * 1000.0).round() as i64,
        )
    };
    let mut count: std::collections::HashMap<(Point, Point), (usize, [f64; 4])> =
        std::collections::HashMap::new();
    for v in polys {
        for k in 0..v.len() {
            let (a, b) = (v[k], v[(k + 1) % v.len()]);
            let (ka, kb) = (key(a), key(b));
            if ka == kb {
                continue;
            }
            let e = count
                .entry((ka.min(kb), ka.max(kb)))
                .or_insert((0, [a[0], a[1], b[0], b[1]]));
            e.0 += 1;
        }
    }
    let mut edges: Vec<[f64; 4]> = count
        .into_values()
        .filter(|(n, _)| *n == 1)
        .map(|(_, e)| e)
        .collect();
    // HashMap order is not stable; the reports are.
    edges.sort_by(|a, b| {
        a.iter()
            .zip(b)
            .map(|(x, y)| x.total_cmp(y))
            .fold(std::cmp::Ordering::Equal, |o, c| o.then(c))
    });
    (edges, floor)
}

/// A copy of `scene` with the diffuse colour of every material of `class` times `k`
/// (capped at 0.95) and glass transmissivity times `tau` (capped at 1).
pub fn scaled_scene(
    scene: &Scene,
    room: &Room,
    class_scales: &[(SurfaceClass, f64)],
    tau: f64,
) -> Scene {
    let mut s = scene.clone();
    for o in &mut s.objects {
        let class = room.materials.iter().find(|m| m.0 == o.id).map(|m| m.1);
        let k = class
            .and_then(|c| class_scales.iter().find(|x| x.0 == c))
            .map(|x| x.1);
        match &mut o.kind {
            Primitive::Plastic { color, .. }
            | Primitive::Metal { color, .. }
            | Primitive::Trans { color, .. } => {
                if let Some(k) = k {
                    color
                        .iter_mut()
                        .for_each(|c| *c = (*c * k).clamp(0.0, 0.95));
                }
            }
            Primitive::Glass { transmissivity, .. } if tau != 1.0 => {
                transmissivity
                    .iter_mut()
                    .for_each(|t| *t = (*t * tau).clamp(0.0, 1.0));
            }
            _ => {}
        }
    }
    s
}

/// Newell's normal of polygon `v` (twice its area long).
fn newell(v: &[[f64; 3]]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for (k, a) in v.iter().enumerate() {
        let b = v[(k + 1) % v.len()];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    n
}

/// Distance along `d` at which the ray from `org` crosses the planar polygon `v`, if it
/// does (Newell normal, then the crossing tested in the plane's dominant projection by the
/// even-odd rule).
fn polygon_hit(v: &[[f64; 3]], org: [f64; 3], d: [f64; 3]) -> Option<f64> {
    let n = newell(v);
    let dn = dot(d, n);
    if dn.abs() < 1e-12 {
        return None;
    }
    let t = dot(sub(v[0], org), n) / dn;
    if t <= 1e-9 {
        return None;
    }
    let p = [org[0] + t * d[0], org[1] + t * d[1], org[2] + t * d[2]];
    // Drop the axis the normal is largest along.
    let ax = (0..3)
        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(2);
    let (i, j) = match ax {
        0 => (1, 2),
        1 => (2, 0),
        _ => (0, 1),
    };
    let mut inside = false;
    for (k, a) in v.iter().enumerate() {
        let b = v[(k + 1) % v.len()];
        if (a[j] > p[j]) != (b[j] > p[j]) {
            let x = a[i] + (p[j] - a[j]) / (b[j] - a[j]) * (b[i] - a[i]);
            if p[i] < x {
                inside = !inside;
            }
        }
    }
    inside.then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Scene {
        crate::scene::parse_str(
            text,
            "t.rad",
            std::path::Path::new(""),
            &crate::scene::LoadOptions::default(),
        )
        .unwrap()
    }

    /// A 2 x 1 m floor in two tiles: the shared edge is inside, so the outline is the six
    /// unit edges of the rectangle's boundary; a table top above it is not floor.
    #[test]
    fn floor_outline_is_the_boundary_of_the_floor_tiles() {
        let floor = "void plastic floor_mat 0 0 5 .3 .3 .3 0 0\n\
                     void plastic table_mat 0 0 5 .5 .5 .5 0 0\n\
                     floor_mat polygon f1 0 0 12 0 0 0 1 0 0 1 1 0 0 1 0\n\
                     floor_mat polygon f2 0 0 12 1 0 0 2 0 0 2 1 0 1 1 0\n\
                     table_mat polygon top 0 0 12 .2 .2 .7 .8 .2 .7 .8 .8 .7 .2 .8 .7\n";
        let room = Room::new(&scene(floor), [1.0, 0.5, 0.8], &[]);
        assert_eq!(room.outline.len(), 6, "{:?}", room.outline);
        let perimeter: f64 = room
            .outline
            .iter()
            .map(|e| ((e[2] - e[0]).powi(2) + (e[3] - e[1]).powi(2)).sqrt())
            .sum();
        assert!((perimeter - 6.0).abs() < 1e-9);
        assert!(room.outline.iter().all(|e| e[0] != 1.0 || e[2] != 1.0));
        // Without a floor-class material: the lowest horizontal polygons under the sensors.
        let unnamed = floor.replace("floor_mat", "grey_mat");
        let room = Room::new(&scene(&unnamed), [1.0, 0.5, 0.8], &[]);
        assert_eq!(room.outline.len(), 6, "{:?}", room.outline);
    }
}
