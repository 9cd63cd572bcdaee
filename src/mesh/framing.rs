//! Putting a mesh into the scene the way the papers frame their heads: its units, its bounds, TAP 2009's three
//! camera distances and its light directions.
//!
//! - **Units.** A mesh is authored in some unit ([`MeshUnits`]): glTF says metres, OBJ says nothing, and a scan is
//!   often in arbitrary units (the Lee Perry-Smith head of the seeds' demos is about 8.6 units wide). The diffusion
//!   kernels are physical widths in mm, so the unit decides how much the skin blurs; [`MeshUnits::HeadHeightMm`]
//!   ("auto") assumes the mesh is a head, y up, and scales its head height ([`head_height_units`]) to an adult's
//!   menton–crown height, [`ADULT_HEAD_HEIGHT_MM`]. A head-only mesh's head height is its y extent; a bust's
//!   (head and shoulders, as the scan) is measured from the crown down to the narrowest slice of the neck.
//! - **Framing.** [`frame_in_metres`] moves the middle of the mesh's head (the bounding box's centre in x and z,
//!   half the head height below the crown in y) to the origin and its positions to metres (the renderer's world
//!   unit), so the camera of `run skin` looks at the face of any head or bust.
//! - **TAP's distances.** Jimenez, Sundstedt & Gutierrez, *Screen-Space Perceptual Rendering of Human Skin*, ACM TAP
//!   6(4), 2009, §6: "The three camera configurations used were at 28, 50, and 132 distance units, which in the
//!   article are referred to zoom, near, and far (for reference, the head is 27 distance units tall)".
//!   [`TapDistance::camera_distance_m`] keeps those ratios to the head's height: d = h · {28, 50, 132}/27.
//! - **TAP's lights.** §6: "a fixed elevation angle θ of 45° and a varying azimuth angle ϕ with values 0° (just in
//!   front of the head), 60°, 110°, and 150° (almost behind of the head)". [`light_direction`] turns (ϕ, θ) into
//!   the unit vector towards the light in the renderer's frame (the head faces +z, the camera is on +z, y is up;
//!   positive azimuths go towards +x, the viewer's right).

use super::Mesh;
use crate::error::{check_range, InvalidInput};

/// Menton–crown height of an adult head, mm: the mean of the 1988 US Army anthropometric survey (Gordon et al.,
/// *1988 Anthropometric Survey of U.S. Army Personnel*, "head height", men 232 mm, women 220 mm), rounded.
pub const ADULT_HEAD_HEIGHT_MM: f32 = 230.0;

/// Height of the head in TAP 2009's experiment, in its distance units (§6).
pub const TAP_HEAD_HEIGHT_UNITS: f32 = 27.0;

/// What one unit of a mesh's positions is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshUnits {
    Millimetres,
    Centimetres,
    Metres,
    Inches,
    /// Any unit, given in millimetres per unit.
    MmPerUnit(f32),
    /// Unknown units: scale the mesh so its height (y extent) is this many mm.
    HeadHeightMm(f32),
}

impl MeshUnits {
    /// The accepted spellings, for messages and `--help`.
    pub const ACCEPTED: &'static str =
        "mm, cm, m, in, auto (height = an adult head's 230 mm) or a number of mm per unit";

    /// Parses `mm`, `cm`, `m`, `in`, `auto` or a positive number of millimetres per unit; `param` names the flag.
    pub fn parse(param: &str, s: &str) -> Result<MeshUnits, InvalidInput> {
        Ok(match s.trim() {
            "mm" => Self::Millimetres,
            "cm" => Self::Centimetres,
            "m" => Self::Metres,
            "in" | "inch" | "inches" => Self::Inches,
            "auto" => Self::HeadHeightMm(ADULT_HEAD_HEIGHT_MM),
            other => {
                let v: f32 = other.parse().map_err(|_| {
                    InvalidInput::new(param, format!("{other:?} is not a unit; accepted: {}", Self::ACCEPTED))
                })?;
                check_range(param, v as f64, 1e-6, 1e9, "mm per unit")?;
                Self::MmPerUnit(v)
            }
        })
    }

    /// Millimetres per unit for a mesh whose height (y extent) is `height_units`.
    pub fn mm_per_unit(self, height_units: f32) -> f32 {
        match self {
            Self::Millimetres => 1.0,
            Self::Centimetres => 10.0,
            Self::Metres => 1000.0,
            Self::Inches => 25.4,
            Self::MmPerUnit(v) => v,
            Self::HeadHeightMm(h) => h / height_units,
        }
    }
}

/// Horizontal slices [`head_height_units`] cuts a mesh into.
const SLICES: usize = 64;

/// The height of the head of a y-up mesh facing +z, in its units: its y extent, or — for a bust, whose lowest
/// quarter is more than 1.6 times as wide (x) as the widest slice of its top half — the distance from the top down
/// to the chin, found where the front of the face falls back: the first slice below the nose tip (the front-most
/// point of the top half) whose front-most z lies more than a quarter of the head's width behind the tip. On the
/// Lee Perry-Smith scan (a bust 7.9 units tall) that gives about 4.6 units, the chin's own level being 4.5 below
/// the crown; on a head-only mesh it is the full height.
pub fn head_height_units(mesh: &Mesh) -> f32 {
    let b = Bounds::of(mesh);
    let (lo, hi) = (b.min[1], b.max[1]);
    let height = hi - lo;
    if height.is_nan() || height <= 0.0 {
        return height;
    }
    // Per slice (slice 0 at the top): x extent and front-most z.
    let mut span = vec![(f32::MAX, f32::MIN); SLICES];
    let mut front = vec![f32::MIN; SLICES];
    for p in &mesh.positions {
        let k = (((hi - p[1]) / height * SLICES as f32) as usize).min(SLICES - 1);
        span[k] = (span[k].0.min(p[0]), span[k].1.max(p[0]));
        front[k] = front[k].max(p[2]);
    }
    let width: Vec<f32> = span.iter().map(|(a, b)| if a <= b { b - a } else { 0.0 }).collect();
    let head_w = width[..SLICES / 2].iter().cloned().fold(0.0f32, f32::max);
    let shoulders = width[3 * SLICES / 4..].iter().cloned().fold(0.0f32, f32::max);
    if shoulders <= 1.6 * head_w {
        return height;
    }
    let nose_k = (0..SLICES / 2).fold(0, |n, k| if front[k] > front[n] { k } else { n });
    match (nose_k..SLICES).find(|&k| front[k] > f32::MIN && front[k] < front[nose_k] - 0.25 * head_w) {
        Some(chin_k) => height * chin_k as f32 / SLICES as f32,
        None => height,
    }
}

/// Axis-aligned bounds of a mesh, in its units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

impl Bounds {
    pub fn of(mesh: &Mesh) -> Bounds {
        let (min, max) = mesh.bounds();
        Bounds { min, max }
    }

    pub fn centre(&self) -> [f32; 3] {
        [0, 1, 2].map(|i| 0.5 * (self.min[i] + self.max[i]))
    }

    pub fn size(&self) -> [f32; 3] {
        [0, 1, 2].map(|i| self.max[i] - self.min[i])
    }

    /// Radius of the sphere round the box.
    pub fn radius(&self) -> f32 {
        let s = self.size();
        0.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
    }
}

/// The mesh with its head's centre (see the code) at the origin and its positions in metres (`mm_per_unit` = 1000), the
/// renderer's world unit; the units come from `units` (`auto` depends on [`head_height_units`]). Normals, UVs and
/// indices are unchanged. Refuses a flat mesh (zero height) under `auto` units, naming `param`.
pub fn frame_in_metres(mesh: &Mesh, units: MeshUnits, param: &str) -> Result<Mesh, InvalidInput> {
    to_metres(mesh, units, MeshOrigin::Head, param)
}

/// Where a mesh's origin goes when it is put in metres.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshOrigin {
    /// The middle of its head ([`frame_in_metres`]).
    Head,
    /// The file's own origin: positions only scaled.
    Authored,
}

/// The mesh in metres (`mm_per_unit` = 1000) with its origin as `origin` says; the units come from `units` (`auto`
/// depends on [`head_height_units`]). Normals, UVs and indices are unchanged. Refuses, naming `param`, a flat mesh
/// (zero height) under `auto` units.
pub fn to_metres(mesh: &Mesh, units: MeshUnits, origin: MeshOrigin, param: &str) -> Result<Mesh, InvalidInput> {
    let b = Bounds::of(mesh);
    let height = head_height_units(mesh);
    if matches!(units, MeshUnits::HeadHeightMm(_)) && (height.is_nan() || height <= 0.0) {
        return Err(InvalidInput::new(param, "auto needs a mesh with a height (y extent) > 0; give the units instead"));
    }
    let to_m = units.mm_per_unit(height) / 1000.0;
    if !(to_m.is_finite() && to_m > 0.0) {
        return Err(InvalidInput::new(param, format!("gives {to_m} m per unit; accepted: {}", MeshUnits::ACCEPTED)));
    }
    let c = match origin {
        // Centre on the head: the box's centre in x and z, the head's middle in y (the box's for a head alone).
        MeshOrigin::Head => {
            let mut c = b.centre();
            c[1] = b.max[1] - 0.5 * height;
            c
        }
        MeshOrigin::Authored => [0.0; 3],
    };
    let positions = mesh.positions.iter().map(|p| [0, 1, 2].map(|i| (p[i] - c[i]) * to_m)).collect();
    Mesh::new(param, positions, mesh.normals.clone(), mesh.uvs.clone(), mesh.indices.clone(), 1000.0)
}

/// TAP 2009's camera distances (§6), named as the article names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TapDistance {
    /// 28 units for a 27-unit head: the face fills the frame (Fig. 7).
    Zoom,
    /// 50 units.
    Near,
    /// 132 units.
    Far,
}

impl TapDistance {
    pub const ALL: [TapDistance; 3] = [Self::Zoom, Self::Near, Self::Far];

    /// The distance in TAP's units.
    pub fn tap_units(self) -> f32 {
        match self {
            Self::Zoom => 28.0,
            Self::Near => 50.0,
            Self::Far => 132.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Zoom => "zoom",
            Self::Near => "near",
            Self::Far => "far",
        }
    }

    pub fn parse(s: &str) -> Option<TapDistance> {
        Self::ALL.into_iter().find(|d| d.name() == s)
    }

    /// Camera distance from the head's centre, m, for a head `head_height_m` tall: TAP's ratio to its 27-unit head.
    pub fn camera_distance_m(self, head_height_m: f32) -> f32 {
        head_height_m * self.tap_units() / TAP_HEAD_HEIGHT_UNITS
    }
}

/// TAP 2009's light azimuths (§6), degrees.
pub const TAP_LIGHT_AZIMUTHS_DEG: [f32; 4] = [0.0, 60.0, 110.0, 150.0];
/// TAP 2009's light elevation (§6), degrees.
pub const TAP_LIGHT_ELEVATION_DEG: f32 = 45.0;

/// Unit vector from the head towards a light at azimuth ϕ (0° in front of the head, on the camera's side; positive
/// towards +x) and elevation θ above the horizontal: (sin ϕ cos θ, sin θ, cos ϕ cos θ). ϕ in −180..=180, θ in
/// −90..=90 degrees (named by `azimuth_param` / `elevation_param` when out of range).
pub fn light_direction(
    azimuth_deg: f32,
    elevation_deg: f32,
    azimuth_param: &str,
    elevation_param: &str,
) -> Result<[f32; 3], InvalidInput> {
    check_range(azimuth_param, azimuth_deg as f64, -180.0, 180.0, "degrees")?;
    check_range(elevation_param, elevation_deg as f64, -90.0, 90.0, "degrees")?;
    let (phi, theta) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    Ok([phi.sin() * theta.cos(), theta.sin(), phi.cos() * theta.cos()])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn box_mesh(scale: f32, offset: [f32; 3]) -> Mesh {
        // Two triangles spanning x 0..2, y 0..4 (height 4), z = 1, in the mesh's units.
        let p = |x: f32, y: f32| [x * scale + offset[0], y * scale + offset[1], scale + offset[2]];
        Mesh::new(
            "box",
            vec![p(0.0, 0.0), p(2.0, 0.0), p(2.0, 4.0), p(0.0, 4.0)],
            vec![[0.0, 0.0, 1.0]; 4],
            vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]],
            vec![0, 1, 2, 0, 2, 3],
            1.0,
        )
        .unwrap()
    }

    #[test]
    fn units_convert_to_metres_and_auto_gives_a_head_height() {
        let m = box_mesh(1.0, [5.0, -3.0, 7.0]);
        let cm = frame_in_metres(&m, MeshUnits::parse("mesh_units", "cm").unwrap(), "mesh_units").unwrap();
        assert_eq!(Bounds::of(&cm).size(), [0.02, 0.04, 0.0]);
        assert_eq!(Bounds::of(&cm).centre(), [0.0, 0.0, 0.0]);
        assert_eq!(cm.mm_per_unit, 1000.0);
        let inch = frame_in_metres(&m, MeshUnits::parse("u", "in").unwrap(), "u").unwrap();
        assert!((Bounds::of(&inch).size()[1] - 4.0 * 0.0254).abs() < 1e-7);
        // The same head authored in arbitrary units at two scales frames to the same metres under "auto".
        for s in [0.37, 8.6, 1234.0] {
            let a =
                frame_in_metres(&box_mesh(s, [1.0, 2.0, 3.0]), MeshUnits::parse("u", "auto").unwrap(), "u").unwrap();
            let h = Bounds::of(&a).size()[1];
            assert!((h - 0.230).abs() < 1e-5, "scale {s}: height {h} m");
        }
        let n = frame_in_metres(&m, MeshUnits::parse("u", "25.4").unwrap(), "u").unwrap();
        assert_eq!(Bounds::of(&n).size(), Bounds::of(&inch).size());
    }

    /// A bust: a 2-wide head with a nose on a 1-wide neck on 6-wide shoulders. Its head height runs from the top
    /// to where the face falls back (the chin, at y = 5).
    #[test]
    fn a_bust_is_measured_from_the_crown_to_the_neck() {
        // Each slab is a strip of quads in x at depth z.
        let slab = |x: f32, z: f32, y0: f32, y1: f32| -> Vec<[f32; 3]> {
            (0..=20)
                .flat_map(|i| {
                    let y = y0 + (y1 - y0) * i as f32 / 20.0;
                    [[-x, y, z], [x, y, z + 0.01]]
                })
                .collect()
        };
        let mut p = slab(3.0, 0.0, 0.0, 3.9); // shoulders, y 0..3.9
        p.extend(slab(0.5, 0.0, 4.0, 4.9)); // neck, y 4..4.9
        p.extend(slab(1.0, 1.0, 5.0, 9.0)); // face, y 5..9, its front at z = 1
        let n = p.len() as u32;
        let idx: Vec<u32> = (0..n - 2).step_by(2).flat_map(|i| [i, i + 1, i + 2]).collect();
        let m = Mesh::new("bust", p, vec![[0.0, 0.0, 1.0]; n as usize], vec![[0.0, 0.0]; n as usize], idx, 1.0);
        let m = m.unwrap();
        let h = head_height_units(&m);
        assert!(h > 3.8 && h < 4.3, "crown (9) to the chin (5): {h}");
        // A head alone is its full height.
        assert_eq!(head_height_units(&box_mesh(1.0, [0.0; 3])), 4.0);
    }

    #[test]
    fn bad_units_name_the_flag_and_the_accepted_values() {
        for bad in ["furlong", "-3", "0", "nan", "inf"] {
            let e = MeshUnits::parse("mesh_units", bad).unwrap_err();
            assert_eq!(e.param, "mesh_units", "{bad}");
        }
        let e = MeshUnits::parse("mesh_units", "furlong").unwrap_err().to_string();
        assert!(e.contains("mm, cm, m, in, auto"), "{e}");
    }

    #[test]
    fn tap_distances_keep_the_papers_ratios() {
        // TAP's own head: 27 units tall at 28, 50 and 132 units.
        for (d, units) in [(TapDistance::Zoom, 28.0), (TapDistance::Near, 50.0), (TapDistance::Far, 132.0)] {
            assert!((d.camera_distance_m(27.0) - units).abs() < 1e-4);
            assert_eq!(TapDistance::parse(d.name()), Some(d));
        }
        assert!((TapDistance::Near.camera_distance_m(0.23) - 0.23 * 50.0 / 27.0).abs() < 1e-7);
        assert_eq!(TapDistance::parse("close"), None);
    }

    #[test]
    fn light_directions_are_unit_and_follow_the_azimuth() {
        let front = light_direction(0.0, 45.0, "a", "e").unwrap();
        assert!((front[0]).abs() < 1e-7 && (front[1] - front[2]).abs() < 1e-6);
        let side = light_direction(90.0, 0.0, "a", "e").unwrap();
        assert!((side[0] - 1.0).abs() < 1e-6 && side[2].abs() < 1e-6);
        // 150°: almost behind the head (negative z, away from the camera).
        let back = light_direction(150.0, 45.0, "a", "e").unwrap();
        assert!(back[2] < -0.6);
        for &az in &TAP_LIGHT_AZIMUTHS_DEG {
            let l = light_direction(az, TAP_LIGHT_ELEVATION_DEG, "a", "e").unwrap();
            assert!(((l[0] * l[0] + l[1] * l[1] + l[2] * l[2]) - 1.0).abs() < 1e-6);
        }
        assert_eq!(light_direction(181.0, 0.0, "light_azimuth_deg", "e").unwrap_err().param, "light_azimuth_deg");
        assert_eq!(light_direction(0.0, 95.0, "a", "light_elevation_deg").unwrap_err().param, "light_elevation_deg");
        assert!(light_direction(f32::NAN, 0.0, "a", "e").is_err());
    }
}
