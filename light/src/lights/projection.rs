//! Projected textures (`_project_texture`): a light that shines a picture, like a slide
//! projector.
//!
//! The picture is one of the BSP's textures, held in front of the light along its projection
//! direction (`_project_mangle`, else `mangle`, else the Half-Life `angles` key) and filling a
//! field of view of `_project_fov` degrees along its longer side. A point the light reaches
//! takes the light's colour times twice the picture's colour where the line from the light
//! through the point crosses the picture (bilinear between texels, ericw-tools' convention: a
//! mid-grey texel passes the light unchanged); a point outside the picture, or less than
//! [`NEAR`] units in front of the light, takes none of it.
//!
//! The picture's up is the light's up (turned by the roll, the third angle); its right is the
//! light's right, so the picture lands on a wall as it reads, seen from the light.

use glam::DVec3;
use quake_formats::miptex::MipTex;
use quake_formats::palette::Palette;

use crate::directions::mangle_to_vec;

/// Default `_project_fov`, degrees.
pub const DEFAULT_FOV: f64 = 90.0;

/// The widest and narrowest `_project_fov` a picture can be shown at, degrees.
pub const FOV_RANGE: std::ops::RangeInclusive<f64> = 1.0..=179.0;

/// Points nearer than this in front of the light (along its projection direction) are outside
/// the picture: the near plane of ericw-tools' projection.
pub const NEAR: f64 = 8.0;

/// What a light entity asks to project, before the BSP's textures are looked at.
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectionKeys {
    /// The light entity's index (every light made from it projects).
    pub entity: usize,
    /// Where the picture is projected from: the entity's `origin`, before any nudge out of
    /// solid (as in ericw-tools).
    pub origin: DVec3,
    pub texture: String,
    /// Yaw, pitch and roll, degrees.
    pub angles: DVec3,
    /// Field of view along the picture's longer side, degrees.
    pub fov: f64,
}

/// A picture held in front of a light.
#[derive(Debug, Clone, PartialEq)]
pub struct Projector {
    origin: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    /// Tangent of half the field of view across and up the picture.
    half_tan: [f64; 2],
    width: usize,
    height: usize,
    /// Colours (0–255) of the picture's texels, rows top to bottom.
    texels: Vec<[f32; 3]>,
}

impl Projector {
    /// The projection `keys` ask for, showing `texture` through `palette`; `None` when the
    /// texture has no pixels in the BSP.
    pub fn new(keys: &ProjectionKeys, texture: &MipTex, palette: &Palette) -> Option<Projector> {
        let pixels = texture.mips.as_ref()?.first()?;
        let (width, height) = (texture.width as usize, texture.height as usize);
        if width == 0 || height == 0 || pixels.len() < width * height {
            return None;
        }
        let texels = pixels[..width * height]
            .iter()
            .map(|&i| palette.colors[usize::from(i)].map(f32::from))
            .collect();
        let [yaw, pitch, roll] = keys.angles.to_array();
        let forward = mangle_to_vec(yaw, pitch);
        let (y, p, r) = (yaw.to_radians(), pitch.to_radians(), roll.to_radians());
        // The light's right and up before the roll; the roll turns both about `forward`.
        let right0 = DVec3::new(y.sin(), -y.cos(), 0.0);
        let up0 = DVec3::new(-y.cos() * p.sin(), -y.sin() * p.sin(), p.cos());
        let right = right0 * r.cos() - up0 * r.sin();
        let up = up0 * r.cos() + right0 * r.sin();
        let half = (keys.fov / 2.0).to_radians().tan();
        let (w, h) = (width as f64, height as f64);
        let half_tan = if width > height {
            [half, half * h / w]
        } else {
            [half * w / h, half]
        };
        Some(Projector {
            origin: keys.origin,
            forward,
            right,
            up,
            half_tan,
            width,
            height,
            texels,
        })
    }

    /// What the light's colour is multiplied by at `point`: twice the picture's colour there
    /// (0–255 becomes 0–2), or 0 outside the picture.
    pub fn tint(&self, point: DVec3) -> DVec3 {
        let v = point - self.origin;
        let depth = v.dot(self.forward);
        if depth < NEAR {
            return DVec3::ZERO;
        }
        // Where the point falls on the picture, 0 to 1 left to right and bottom to top.
        let across = (1.0 + v.dot(self.right) / (depth * self.half_tan[0])) / 2.0;
        let upward = (1.0 + v.dot(self.up) / (depth * self.half_tan[1])) / 2.0;
        if !(across > 0.0 && across < 1.0 && upward > 0.0 && upward < 1.0) {
            return DVec3::ZERO;
        }
        let s = across * (self.width - 1) as f64;
        let t = (1.0 - upward) * (self.height - 1) as f64;
        let (s0, t0) = (s.floor(), t.floor());
        let (fs, ft) = (s - s0, t - t0);
        let (s0, t0) = (s0 as usize, t0 as usize);
        let texel = |s: usize, t: usize| {
            let c = self.texels[(t % self.height) * self.width + s % self.width];
            DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]))
        };
        let mixed = texel(s0, t0) * ((1.0 - fs) * (1.0 - ft))
            + texel(s0 + 1, t0) * (fs * (1.0 - ft))
            + texel(s0, t0 + 1) * ((1.0 - fs) * ft)
            + texel(s0 + 1, t0 + 1) * (fs * ft);
        mixed * (2.0 / 255.0)
    }

    /// Whether every texel of the picture is grey (the light stays its own colour's hue).
    pub fn is_grey(&self) -> bool {
        self.texels.iter().all(|c| c[0] == c[1] && c[1] == c[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4x2 picture: texel (s, t) has red `s * 60`, green `t * 200`, blue 100.
    fn picture() -> (MipTex, Palette) {
        let mut palette = Palette::slipgate();
        let mut pixels = Vec::new();
        for t in 0..2u8 {
            for s in 0..4u8 {
                let index = t * 4 + s;
                palette.colors[usize::from(index)] = [s * 60, t * 200, 100];
                pixels.push(index);
            }
        }
        let tex = MipTex::new("pic", 4, 2, [pixels, vec![], vec![], vec![]]);
        (tex, palette)
    }

    fn keys(angles: DVec3, fov: f64) -> ProjectionKeys {
        ProjectionKeys {
            entity: 0,
            origin: DVec3::ZERO,
            texture: "pic".into(),
            angles,
            fov,
        }
    }

    #[test]
    fn the_middle_of_the_picture_lands_on_the_axis() {
        let (tex, palette) = picture();
        // Shining straight down: the point below the light is the picture's middle, between
        // all four middle texels.
        let p = Projector::new(&keys(DVec3::new(0.0, -90.0, 0.0), 90.0), &tex, &palette)
            .expect("a picture");
        let tint = p.tint(DVec3::new(0.0, 0.0, -100.0));
        let expect = DVec3::new(90.0, 100.0, 100.0) * (2.0 / 255.0);
        assert!((tint - expect).length() < 1e-9, "{tint}");
    }

    #[test]
    fn the_picture_reads_left_to_right_and_top_to_bottom_seen_from_the_light() {
        let (tex, palette) = picture();
        // Looking along +x, right is -y and up is +z.
        let p = Projector::new(&keys(DVec3::ZERO, 90.0), &tex, &palette).expect("a picture");
        // The wider side spans 90 degrees: at 100 units out, y from +100 (left) to -100
        // (right); the picture is half as tall: z from -50 to +50.
        let top_left = p.tint(DVec3::new(100.0, 99.0, 49.0));
        let bottom_right = p.tint(DVec3::new(100.0, -99.0, -49.0));
        assert!(top_left.x < 0.05 && top_left.y < 0.05, "{top_left}");
        assert!(
            bottom_right.x > 1.35 && bottom_right.y > 1.5,
            "{bottom_right}"
        );
        // Outside the picture, behind the light, and too near: nothing.
        for outside in [
            DVec3::new(100.0, 101.0, 0.0),
            DVec3::new(100.0, 0.0, 51.0),
            DVec3::new(-100.0, 0.0, 0.0),
            DVec3::new(NEAR - 0.5, 0.0, 0.0),
        ] {
            assert_eq!(p.tint(outside), DVec3::ZERO, "{outside}");
        }
    }

    #[test]
    fn roll_turns_the_picture_and_fov_widens_it() {
        let (tex, palette) = picture();
        // Rolled a quarter turn, the longer side stands up: z now reaches +-99 at 100 out.
        let rolled =
            Projector::new(&keys(DVec3::new(0.0, 0.0, 90.0), 90.0), &tex, &palette).expect("");
        assert_ne!(rolled.tint(DVec3::new(100.0, 0.0, 99.0)), DVec3::ZERO);
        assert_eq!(rolled.tint(DVec3::new(100.0, 99.0, 0.0)), DVec3::ZERO);
        // At 60 degrees the picture is narrower: y = 99 at 100 out falls outside.
        let narrow = Projector::new(&keys(DVec3::ZERO, 60.0), &tex, &palette).expect("");
        assert_eq!(narrow.tint(DVec3::new(100.0, 99.0, 0.0)), DVec3::ZERO);
        assert_ne!(narrow.tint(DVec3::new(100.0, 50.0, 0.0)), DVec3::ZERO);
    }

    #[test]
    fn a_texture_without_pixels_projects_nothing() {
        let tex = MipTex {
            raw_name: [0; 16],
            width: 64,
            height: 64,
            mips: None,
        };
        let keys = keys(DVec3::ZERO, 90.0);
        assert!(Projector::new(&keys, &tex, &Palette::slipgate()).is_none());
    }
}
