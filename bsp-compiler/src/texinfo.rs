//! Texture projections of both `.map` formats, and what a texture name means to the compiler.

use glam::DVec3;
use quake_formats::bsp::contents;
use quake_formats::geom::Plane;

/// How a face's texture is projected, as written in the `.map` file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Quake's format: axes picked from the face normal, then rotated, scaled and shifted.
    Standard {
        /// Texels added to s and t.
        shift: [f64; 2],
        /// Degrees the axes are turned by.
        rotation: f64,
        /// World units per texel along s and t (0 means 1).
        scale: [f64; 2],
    },
    /// Valve 220: explicit axes with offsets, then scaled.
    Valve {
        /// The s axis, then its offset in texels.
        u: [f64; 4],
        /// The t axis, then its offset in texels.
        v: [f64; 4],
        /// World units per texel along s and t (0 means 1).
        scale: [f64; 2],
    },
}

/// For each of the six base directions: the normal it matches, then the s and t axes.
const BASE_AXES: [[DVec3; 3]; 6] = [
    [
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, -1.0, 0.0),
    ],
    [
        DVec3::new(0.0, 0.0, -1.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, -1.0, 0.0),
    ],
    [
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
    ],
    [
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
    ],
    [
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
    ],
    [
        DVec3::new(0.0, -1.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
    ],
];

/// The s and t axes Quake projects a face with `normal` onto, before rotation and scale: those
/// of the closest base direction (earlier entries win ties, as in Quake).
pub(crate) fn base_axes(normal: DVec3) -> [DVec3; 2] {
    let mut best = 0;
    let mut best_dot = 0.0;
    for (i, axes) in BASE_AXES.iter().enumerate() {
        let d = normal.dot(axes[0]);
        if d > best_dot {
            best_dot = d;
            best = i;
        }
    }
    [BASE_AXES[best][1], BASE_AXES[best][2]]
}

fn nonzero_scale(s: f64) -> f64 {
    if s == 0.0 { 1.0 } else { s }
}

impl Projection {
    /// The texinfo vectors (`s = p·vecs[0].xyz + vecs[0].w`) for a face on `plane`.
    pub fn vecs(&self, plane: &Plane) -> [[f64; 4]; 2] {
        match *self {
            Projection::Valve { u, v, scale } => {
                let (su, sv) = (nonzero_scale(scale[0]), nonzero_scale(scale[1]));
                [
                    [u[0] / su, u[1] / su, u[2] / su, u[3]],
                    [v[0] / sv, v[1] / sv, v[2] / sv, v[3]],
                ]
            }
            Projection::Standard {
                shift,
                rotation,
                scale,
            } => {
                let mut axes = base_axes(plane.normal);
                let (sin, cos) = match rotation {
                    0.0 => (0.0, 1.0),
                    90.0 => (1.0, 0.0),
                    180.0 => (0.0, -1.0),
                    270.0 => (-1.0, 0.0),
                    r => r.to_radians().sin_cos(),
                };
                let first_nonzero = |v: DVec3| (0..3).find(|&i| v[i] != 0.0).unwrap_or(2);
                let sv = first_nonzero(axes[0]);
                let tv = first_nonzero(axes[1]);
                for axis in &mut axes {
                    let (s, t) = (axis[sv], axis[tv]);
                    axis[sv] = cos * s - sin * t;
                    axis[tv] = sin * s + cos * t;
                }
                let mut out = [[0.0; 4]; 2];
                for i in 0..2 {
                    let sc = nonzero_scale(scale[i]);
                    out[i] = [axes[i].x / sc, axes[i].y / sc, axes[i].z / sc, shift[i]];
                }
                out
            }
        }
    }
}

/// What a texture name tells the compiler about a face and its brush.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TextureRole {
    /// Drawn and lit.
    Normal,
    /// `sky*`: drawn unlit, makes its brush sky.
    Sky,
    /// `*name`: drawn unlit and warped, makes its brush a liquid (water, slime or lava).
    Liquid(i32),
    /// `*waterskip`, `*slimeskip`, `*lavaskip`: makes its brush that liquid, and is not drawn
    /// (an invisible liquid, as in ericw-tools).
    LiquidSkip(i32),
    /// `clip`: the brush only exists in the clip hulls.
    Clip,
    /// `skip`: the face is dropped.
    Skip,
    /// `trigger`: the face is not drawn.
    Trigger,
    /// `hint`: a splitter only; the brush is neither drawn nor solid.
    Hint,
    /// `hintskip`: a face of a hint brush that does not split.
    HintSkip,
    /// `origin`: the brush marks a brush entity's origin (its centre), and is not built.
    Origin,
}

impl TextureRole {
    pub fn of(name: &str) -> TextureRole {
        let lower = name.to_ascii_lowercase();
        match lower.as_str() {
            "*waterskip" => return TextureRole::LiquidSkip(contents::WATER),
            "*slimeskip" => return TextureRole::LiquidSkip(contents::SLIME),
            "*lavaskip" => return TextureRole::LiquidSkip(contents::LAVA),
            _ => {}
        }
        if lower.starts_with("sky") {
            TextureRole::Sky
        } else if let Some(rest) = lower.strip_prefix('*') {
            TextureRole::Liquid(if rest.contains("lava") {
                contents::LAVA
            } else if rest.contains("slime") {
                contents::SLIME
            } else {
                contents::WATER
            })
        } else {
            match lower.as_str() {
                "clip" => TextureRole::Clip,
                "skip" => TextureRole::Skip,
                "trigger" => TextureRole::Trigger,
                "origin" => TextureRole::Origin,
                "hint" => TextureRole::Hint,
                "hintskip" => TextureRole::HintSkip,
                _ => TextureRole::Normal,
            }
        }
    }

    /// Faces with these textures get no lightmap and are not subdivided (`TEX_SPECIAL`): sky,
    /// and liquids unless they are lit (ericw-tools' `-litwater`; engines that do not light
    /// liquids draw them fullbright either way).
    pub fn is_special(self, lit_water: bool) -> bool {
        match self {
            TextureRole::Sky => true,
            TextureRole::Liquid(_) | TextureRole::LiquidSkip(_) => !lit_water,
            _ => false,
        }
    }

    /// Faces with these textures never become BSP faces.
    pub fn is_drawn(self) -> bool {
        !matches!(
            self,
            TextureRole::Clip
                | TextureRole::Skip
                | TextureRole::LiquidSkip(_)
                | TextureRole::Trigger
                | TextureRole::Hint
                | TextureRole::HintSkip
                | TextureRole::Origin
        )
    }
}

/// What a face's texture makes of its brush.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceContents {
    /// Any other texture, `skip` and `trigger` included: the brush is solid.
    Solid,
    /// `sky*`: the brush is sky.
    Sky,
    /// `*name`: the brush is a liquid (water, slime or lava, as a
    /// `quake_formats::bsp::contents` value).
    Liquid(i32),
    /// `clip`: the brush only exists in the clip hulls.
    Clip,
}

impl FaceContents {
    /// The contents a face of `role` gives its brush; `None` for faces that give none (hint,
    /// hintskip, origin).
    pub(crate) fn of(role: TextureRole) -> Option<FaceContents> {
        match role {
            TextureRole::Sky => Some(FaceContents::Sky),
            TextureRole::Liquid(c) | TextureRole::LiquidSkip(c) => Some(FaceContents::Liquid(c)),
            TextureRole::Clip => Some(FaceContents::Clip),
            TextureRole::Hint | TextureRole::HintSkip | TextureRole::Origin => None,
            TextureRole::Normal | TextureRole::Skip | TextureRole::Trigger => {
                Some(FaceContents::Solid)
            }
        }
    }
}

impl std::fmt::Display for FaceContents {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FaceContents::Solid => "solid",
            FaceContents::Sky => "sky",
            FaceContents::Liquid(contents::LAVA) => "lava",
            FaceContents::Liquid(contents::SLIME) => "slime",
            FaceContents::Liquid(_) => "water",
            FaceContents::Clip => "clip",
        })
    }
}

/// A brush's contents from its faces' textures, as id's and ericw-tools' compilers decide them:
/// the first face that gives any decides (solid when none does). When a later face gives other
/// contents, that face's index comes too, for a warning.
pub(crate) fn brush_contents(roles: &[TextureRole]) -> (FaceContents, Option<usize>) {
    let mut faces = roles
        .iter()
        .enumerate()
        .filter_map(|(i, &r)| Some((i, FaceContents::of(r)?)));
    let Some((_, first)) = faces.next() else {
        return (FaceContents::Solid, None);
    };
    let conflict = faces.find(|&(_, c)| c != first).map(|(i, _)| i);
    (first, conflict)
}

/// A frame of an animated texture: `+`, the frame, then the name all frames of the animation
/// share. Frames `0`-`9` are the main cycle, `a`-`j` the alternate one engines show on an
/// entity whose frame is 1 (a pressed button).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct AnimationFrame<'a> {
    pub base: &'a str,
    pub alternate: bool,
    /// 0 to 9 within its cycle.
    pub index: u8,
}

impl<'a> AnimationFrame<'a> {
    /// `None` for a name without a leading `+`, or whose frame is out of range (which
    /// QuakeSpasm refuses to load).
    pub fn of(name: &'a str) -> Option<AnimationFrame<'a>> {
        let rest = name.strip_prefix('+')?;
        let frame = rest.chars().next()?.to_ascii_lowercase();
        let (alternate, index) = match frame {
            '0'..='9' => (false, frame as u8 - b'0'),
            'a'..='j' => (true, frame as u8 - b'a'),
            _ => return None,
        };
        Some(AnimationFrame {
            base: &rest[1..],
            alternate,
            index,
        })
    }

    /// The name of frame `index` (0 to 9) of this animation's main or alternate cycle.
    pub fn sibling(&self, alternate: bool, index: u8) -> String {
        let first = if alternate { b'a' } else { b'0' };
        format!("+{}{}", char::from(first + index), self.base)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::DVec3Ext;

    #[test]
    fn a_brushs_first_face_that_gives_contents_decides_them() {
        let role = |names: &[&str]| names.iter().map(|n| TextureRole::of(n)).collect::<Vec<_>>();
        let sky = FaceContents::Sky;
        assert_eq!(
            brush_contents(&role(&["sky1", "sky1", "sky1"])),
            (sky, None)
        );
        assert_eq!(
            brush_contents(&role(&["sky1", "brick", "sky1"])),
            (sky, Some(1))
        );
        assert_eq!(
            brush_contents(&role(&["brick", "sky1", "sky1"])),
            (FaceContents::Solid, Some(1))
        );
        // skip is solid: first, it makes a water brush solid (ericw-tools does too).
        let water = FaceContents::Liquid(contents::WATER);
        assert_eq!(
            brush_contents(&role(&["skip", "*water1", "*water1"])),
            (FaceContents::Solid, Some(1))
        );
        assert_eq!(
            brush_contents(&role(&["*water1", "*water1", "skip"])),
            (water, Some(2))
        );
        // Hint faces give none; a brush of them alone is solid (and a hint brush elsewhere).
        assert_eq!(brush_contents(&role(&["hint", "*water1"])), (water, None));
        assert_eq!(
            brush_contents(&role(&["hint", "hintskip"])),
            (FaceContents::Solid, None)
        );
        assert_eq!(
            brush_contents(&role(&["clip", "brick"])),
            (FaceContents::Clip, Some(1))
        );
    }

    #[test]
    fn animation_frames_from_names() {
        let f = AnimationFrame::of("+3butnn").expect("animated");
        assert_eq!((f.base, f.alternate, f.index), ("butnn", false, 3));
        assert_eq!(f.sibling(false, 0), "+0butnn");
        assert_eq!(f.sibling(true, 9), "+jbutnn");
        let f = AnimationFrame::of("+Bbutnn").expect("alternate");
        assert_eq!((f.base, f.alternate, f.index), ("butnn", true, 1));
        assert_eq!(AnimationFrame::of("+kbutnn"), None);
        assert_eq!(AnimationFrame::of("+"), None);
        assert_eq!(AnimationFrame::of("butnn"), None);
    }

    fn standard(shift: [f64; 2], rotation: f64, scale: [f64; 2]) -> Projection {
        Projection::Standard {
            shift,
            rotation,
            scale,
        }
    }

    fn plane(n: DVec3) -> Plane {
        Plane::new(n, 0.0)
    }

    #[test]
    fn floor_uses_x_and_minus_y() {
        let v = standard([0.0, 0.0], 0.0, [1.0, 1.0]).vecs(&plane(DVec3::new(0.0, 0.0, 1.0)));
        assert_eq!(v, [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]]);
    }

    #[test]
    fn walls_use_their_base_axes() {
        let v = standard([0.0, 0.0], 0.0, [1.0, 1.0]).vecs(&plane(DVec3::new(-1.0, 0.0, 0.0)));
        assert_eq!(v, [[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0]]);
        let v = standard([0.0, 0.0], 0.0, [1.0, 1.0]).vecs(&plane(DVec3::new(0.0, 1.0, 0.0)));
        assert_eq!(v, [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0]]);
    }

    #[test]
    fn rotation_scale_and_shift() {
        // e1m1's "SLIPBOTSD 0 0 90 -1 1" on an X wall.
        let v = standard([0.0, 0.0], 90.0, [-1.0, 1.0]).vecs(&plane(DVec3::new(1.0, 0.0, 0.0)));
        // s axis (0,1,0) rotated by 90 becomes (0,0,1); t axis (0,0,-1) becomes (0,1,0).
        assert_eq!(v[0], [0.0, 0.0, -1.0, 0.0]);
        assert_eq!(v[1], [0.0, 1.0, 0.0, 0.0]);
        let v = standard([16.0, -8.0], 0.0, [2.0, 0.5]).vecs(&plane(DVec3::new(0.0, 0.0, 1.0)));
        assert_eq!(v, [[0.5, 0.0, 0.0, 16.0], [0.0, -2.0, 0.0, -8.0]]);
    }

    #[test]
    fn sloped_face_picks_the_closest_axis() {
        let n = DVec3::new(0.6, 0.0, 0.8);
        let v = standard([0.0, 0.0], 0.0, [1.0, 1.0]).vecs(&plane(n));
        assert_eq!(v[0], [1.0, 0.0, 0.0, 0.0]);
        let n = DVec3::new(0.8, 0.0, 0.6);
        let v = standard([0.0, 0.0], 0.0, [1.0, 1.0]).vecs(&plane(n));
        assert_eq!(v[0], [0.0, 1.0, 0.0, 0.0]);
    }

    #[test]
    fn valve_axes_are_divided_by_scale() {
        let p = Projection::Valve {
            u: [0.0, 1.0, 0.0, -16.0],
            v: [0.0, 0.0, -1.0, 4.0],
            scale: [0.5, 2.0],
        };
        let v = p.vecs(&plane(DVec3::new(1.0, 0.0, 0.0)));
        assert_eq!(v, [[0.0, 2.0, 0.0, -16.0], [0.0, 0.0, -0.5, 4.0]]);
    }

    #[test]
    fn roles_from_names() {
        assert_eq!(TextureRole::of("SKY4"), TextureRole::Sky);
        assert_eq!(
            TextureRole::of("*lava1"),
            TextureRole::Liquid(contents::LAVA)
        );
        assert_eq!(
            TextureRole::of("*04mwat2"),
            TextureRole::Liquid(contents::WATER)
        );
        assert_eq!(TextureRole::of("CLIP"), TextureRole::Clip);
        assert_eq!(TextureRole::of("wall1"), TextureRole::Normal);
        assert!(TextureRole::of("*slime0").is_special(false));
        assert!(!TextureRole::of("*slime0").is_special(true));
        assert!(TextureRole::of("sky4").is_special(true));
        assert!(!TextureRole::of("skip").is_drawn());
        // ericw-tools' invisible liquids, by their exact names only.
        assert_eq!(
            TextureRole::of("*WaterSkip"),
            TextureRole::LiquidSkip(contents::WATER)
        );
        assert!(!TextureRole::of("*lavaskip").is_drawn());
        assert_eq!(
            FaceContents::of(TextureRole::of("*slimeskip")),
            Some(FaceContents::Liquid(contents::SLIME))
        );
        assert!(TextureRole::of("*teleskip").is_drawn());
    }

    proptest::proptest! {
        /// On any plane, a standard projection maps points to texture coordinates one to one,
        /// so every texel position belongs to exactly one point of the face.
        #[test]
        fn standard_projections_invert(
            n in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            rotation in -360.0f64..360.0,
            scale in (0.1f64..4.0, 0.1f64..4.0),
            negate in (proptest::bool::ANY, proptest::bool::ANY),
        ) {
            let Some(normal) = DVec3::new(n.0, n.1, n.2).normalized() else {
                return Ok(());
            };
            let scale = [
                if negate.0 { -scale.0 } else { scale.0 },
                if negate.1 { -scale.1 } else { scale.1 },
            ];
            let v = standard([3.0, -7.0], rotation, scale).vecs(&plane(normal));
            let s = DVec3::new(v[0][0], v[0][1], v[0][2]);
            let t = DVec3::new(v[1][0], v[1][1], v[1][2]);
            // The area the plane's unit square covers in texture space: zero means two points
            // share texture coordinates.
            let covered = s.cross(t).dot(normal).abs();
            proptest::prop_assert!(covered > 1e-3 / (scale[0] * scale[1]).abs(), "{:?} {:?}", s, t);
        }
    }
}
