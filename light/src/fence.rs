//! Fence textures (names starting with `{`) are drawn with holes where their texels are palette
//! index 255, and light goes through those holes, as in ericw-tools: a grate's shadow is a
//! grate. Fence faces that cast shadows are kept out of the opaque scene, in a scene of their
//! own. A shadow or sun ray meets them there: at an opaque texel it is blocked; at an open one
//! it goes on from just past the face, to the next fence face or its end. Dirt and bounced light
//! look at the opaque scene only, so fences neither darken corners nor reflect light.
//!
//! The inside of a `func_detail_fence` is written as solid leaves, which stop players as the
//! fence should; the compiler marks them (`SLIPGATE_LEAFFLAGS`), and light takes them as open
//! space, as ericw-tools' light does from its qbsp's extended contents: samples and lights
//! inside a fence are not in solid.

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Arc;

use glam::{DVec3, Vec3};
use quake_formats::Bsp;
use quake_formats::geom::Bounds;
use quake_formats::miptex::MipTex;

use crate::embree::{Device, RayPacket16, Scene, sys};
use crate::error::LightError;
use crate::faces::FaceGeom;
use crate::mesh::Mesh;

/// The palette index fence textures leave transparent.
const OPEN_TEXEL: u8 = 255;

/// How many fence faces one ray may pass through before it counts as blocked.
const MAX_LAYERS: usize = 16;

/// How far past an open texel a ray goes on from, so it does not meet the same face again.
const STEP_PAST: f32 = 0.01;

/// `bsp` as light sees it: the leaves the compiler marks as inside a fence are open (empty).
///
/// # Errors
/// [`LightError::BspxLump`] when the leaf flags do not read.
pub fn with_fence_leaves_open(bsp: &Bsp) -> Result<Cow<'_, Bsp>, LightError> {
    let Some(flags) = bsp.leaf_flags().map_err(LightError::BspxLump)? else {
        return Ok(Cow::Borrowed(bsp));
    };
    if !flags.iter().any(|f| f.fence) {
        return Ok(Cow::Borrowed(bsp));
    }
    let mut open = bsp.clone();
    for (leaf, flags) in open.leafs.iter_mut().zip(&flags) {
        if flags.fence {
            leaf.contents = quake_formats::bsp::contents::EMPTY;
        }
    }
    Ok(Cow::Owned(open))
}

/// Which texels of a fence texture's full-size picture are open.
#[derive(Debug, Clone, PartialEq)]
pub struct TexelMask {
    width: usize,
    height: usize,
    open: Vec<bool>,
}

impl TexelMask {
    /// The mask of `mip`'s first level; `None` when the texture has no pixels in the BSP (an
    /// external WAD's), or no open texel (it then blocks light like any face).
    pub fn of(mip: &MipTex) -> Option<TexelMask> {
        let (width, height) = (mip.width as usize, mip.height as usize);
        let pixels = mip
            .mips
            .as_ref()?
            .first()
            .filter(|p| p.len() == width * height)?;
        let open: Vec<bool> = pixels.iter().map(|&p| p == OPEN_TEXEL).collect();
        open.contains(&true).then_some(TexelMask {
            width,
            height,
            open,
        })
    }

    /// Whether the texel at texture coordinates (`s`, `t`) is open (the texture tiles).
    fn is_open(&self, s: f64, t: f64) -> bool {
        let x = (s.floor() as i64).rem_euclid(self.width as i64) as usize;
        let y = (t.floor() as i64).rem_euclid(self.height as i64) as usize;
        self.open[y * self.width + x]
    }
}

/// The texel masks of the fence textures of `bsp`'s faces, by face index.
pub fn fence_masks(bsp: &Bsp, faces: &[FaceGeom]) -> Vec<(usize, Arc<TexelMask>)> {
    let mut by_texture: HashMap<&str, Option<Arc<TexelMask>>> = HashMap::new();
    let mut out = Vec::new();
    for f in faces.iter().filter(|f| f.is_fence()) {
        let mask = by_texture.entry(&f.texture).or_insert_with(|| {
            let index = bsp.textures.find(&f.texture)?;
            let mip = bsp.textures.textures.get(index)?.as_ref()?;
            TexelMask::of(mip).map(Arc::new)
        });
        if let Some(mask) = mask {
            out.push((f.index, mask.clone()));
        }
    }
    out
}

/// One fence face: where its texture lies on it.
#[derive(Debug)]
struct FenceFace {
    mask: Arc<TexelMask>,
    /// Texture projection in model space.
    vecs: [[f32; 4]; 2],
    /// Model space is world space less this.
    origin: DVec3,
}

impl FenceFace {
    fn is_open_at(&self, p: DVec3) -> bool {
        let q = p - self.origin;
        let st = |row: &[f32; 4]| {
            Vec3::new(row[0], row[1], row[2]).as_dvec3().dot(q) + f64::from(row[3])
        };
        self.mask.is_open(st(&self.vecs[0]), st(&self.vecs[1]))
    }
}

/// Boxes around the fence faces, [`BOX_MARGIN`] wider each way: a ray whose segment's box
/// meets none of them meets no fence, and needs no walk through the fence scene (a packet's
/// walk costs about as much on a few small signs as on many faces).
#[derive(Debug)]
struct FenceBoxes {
    all: Box32,
    /// One per face; empty past [`MAX_FACE_BOXES`] faces, where `all` alone is tested.
    each: Vec<Box32>,
}

/// A box in the rays' single precision, `(mins, maxs)`.
type Box32 = ([f32; 3], [f32; 3]);

/// Room around the boxes for the rounding of a segment's ends (rays are single precision).
const BOX_MARGIN: f64 = 1.0;

/// Faces beyond which a ray is tested against the box of all fences only.
const MAX_FACE_BOXES: usize = 64;

impl FenceBoxes {
    /// The boxes of the fence faces with these corners.
    fn new<'a>(faces: impl Iterator<Item = &'a [DVec3]>) -> FenceBoxes {
        let box_of = |points: &[DVec3]| {
            let mut b = Bounds::EMPTY;
            for &p in points {
                b.add_point(p);
            }
            Bounds {
                mins: b.mins - BOX_MARGIN,
                maxs: b.maxs + BOX_MARGIN,
            }
        };
        let each: Vec<Bounds> = faces.map(box_of).collect();
        let all = each.iter().fold(Bounds::EMPTY, |acc, b| acc.union(b));
        let single = |b: &Bounds| (b.mins.as_vec3().to_array(), b.maxs.as_vec3().to_array());
        FenceBoxes {
            all: single(&all),
            each: if each.len() <= MAX_FACE_BOXES {
                each.iter().map(single).collect()
            } else {
                Vec::new()
            },
        }
    }

    /// Of `lanes` of `packet`, those whose segment's box meets a fence face's box (and those
    /// whose segment has no finite box). A face's box is tested lane by lane only when it
    /// meets the box of all the lanes' segments: a packet's rays are close together, and
    /// fences are usually a few small signs.
    fn lanes_near(&self, packet: &RayPacket16, lanes: u16) -> u16 {
        crate::simd::widest(
            #[inline(always)]
            || self.lanes_near_any(packet, lanes),
        )
    }

    /// [`FenceBoxes::lanes_near`] for whatever the build targets.
    #[inline(always)]
    fn lanes_near_any(&self, packet: &RayPacket16, lanes: u16) -> u16 {
        let segments = packet.segment_boxes();
        let unbounded = segments.unbounded & lanes;
        let mut near = segments.meeting(self.all.0, self.all.1) & lanes;
        if near == 0 || self.each.is_empty() {
            return near | unbounded;
        }
        let (mins, maxs) = segments.union();
        let mut by_face = 0;
        for &(face_mins, face_maxs) in &self.each {
            let meets_union = (0..3).all(|a| mins[a] <= face_maxs[a] && face_mins[a] <= maxs[a]);
            if meets_union {
                by_face |= segments.meeting(face_mins, face_maxs);
                if by_face & near == near {
                    break;
                }
            }
        }
        near &= by_face;
        near | unbounded
    }
}

/// The shadow-casting fence faces, in a scene of their own.
pub struct Fences {
    scene: Scene,
    /// The place in `faces` of each triangle's face (by primitive id).
    triangles: Vec<u32>,
    faces: Vec<FenceFace>,
    boxes: FenceBoxes,
}

impl Fences {
    /// A scene of `faces`, each with its texel mask; `None` when there are none.
    pub fn build(
        device: &Device,
        faces: &[(&FaceGeom, Arc<TexelMask>)],
    ) -> Result<Option<Fences>, LightError> {
        if faces.is_empty() {
            return Ok(None);
        }
        // Thinned: the walls around a fence put points on its edges that only slow its rays.
        let numbered: Vec<(&FaceGeom, u32)> = faces
            .iter()
            .zip(0..)
            .map(|((face, _), k)| (*face, k))
            .collect();
        let mesh = Mesh::thinned(&numbered);
        let mut fence_faces = Vec::with_capacity(faces.len());
        for (face, mask) in faces {
            fence_faces.push(FenceFace {
                mask: mask.clone(),
                vecs: face.vecs,
                origin: face.origin,
            });
        }
        Ok(Some(Fences {
            scene: mesh.commit(device)?,
            triangles: mesh.faces,
            faces: fence_faces,
            boxes: FenceBoxes::new(faces.iter().map(|(f, _)| &f.points[..])),
        }))
    }

    /// Of `lanes` of `packet` (each over its segment), those a fence face blocks at an opaque
    /// texel. `packet` itself is left as it was.
    pub fn blocks16(&self, packet: &RayPacket16, lanes: u16) -> u16 {
        let lanes = self.boxes.lanes_near(packet, lanes);
        if lanes == 0 {
            return 0;
        }
        let segments: [Option<_>; 16] =
            std::array::from_fn(|lane| packet.segment(lane).filter(|_| lanes & (1 << lane) != 0));
        let mut probe = *packet;
        probe.keep_shortened(lanes, 1.0);
        let mut blocked = 0u16;
        for _ in 0..MAX_LAYERS {
            let hits = self.scene.first_hits16(&mut probe, false);
            let mut again = 0u16;
            for (lane, &(geom, prim)) in hits.iter().enumerate() {
                let Some((org, dir, _, far)) = segments[lane] else {
                    continue;
                };
                if geom == sys::RTC_INVALID_GEOMETRY_ID {
                    continue;
                }
                let t = probe.tfar(lane);
                let at = Vec3::from(org).as_dvec3() + Vec3::from(dir).as_dvec3() * f64::from(t);
                let open = self
                    .triangles
                    .get(prim as usize)
                    .and_then(|&k| self.faces.get(k as usize))
                    .is_some_and(|f| f.is_open_at(at));
                if open {
                    again |= 1 << lane;
                    probe.set(lane, org, dir, t + STEP_PAST, far);
                } else {
                    blocked |= 1 << lane;
                }
            }
            if again == 0 {
                return blocked;
            }
            probe.keep_shortened(again, 1.0);
        }
        // Still passing through fences after so many: count it as blocked.
        blocked | probe.active_mask()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`FenceBoxes::lanes_near`] as each vector build this CPU runs compiles it, checked to
    /// agree.
    fn lanes_near_in_every_build(boxes: &FenceBoxes, packet: &RayPacket16, lanes: u16) -> u16 {
        let each = crate::simd::builds_here(
            #[inline(always)]
            || boxes.lanes_near_any(packet, lanes),
        );
        let (_, first) = each[0];
        for (build, near) in each {
            assert_eq!(near, first, "{build:?}");
        }
        first
    }

    #[test]
    fn a_ray_near_a_fence_face_is_walked_and_one_far_from_all_is_not() {
        let face = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 64.0, 0.0),
            DVec3::new(0.0, 64.0, 64.0),
            DVec3::new(0.0, 0.0, 64.0),
        ];
        let boxes = FenceBoxes::new(std::iter::once(&face[..]));
        let mut packet = RayPacket16::new();
        // Through the face; ending half a unit short of its plane (within the margin); beside
        // it; and far from it.
        packet.set(0, [-32.0, 32.0, 32.0], [1.0, 0.0, 0.0], 0.0, 64.0);
        packet.set(1, [-32.0, 32.0, 32.0], [1.0, 0.0, 0.0], 0.0, 31.5);
        packet.set(2, [-32.0, 200.0, 32.0], [1.0, 0.0, 0.0], 0.0, 64.0);
        packet.set(3, [500.0, 500.0, 500.0], [0.0, 0.0, 1.0], 0.0, 100.0);
        assert_eq!(lanes_near_in_every_build(&boxes, &packet, 0b1111), 0b0011);
        assert_eq!(
            lanes_near_in_every_build(&boxes, &packet, 0b0010),
            0b0010,
            "only the lanes asked"
        );
    }

    #[test]
    fn each_lane_is_tested_against_every_face_its_packet_reaches() {
        // Small signs along a corridor, and rays along it ending beside different signs: the
        // packet's box meets all of them, each lane only those its own segment reaches.
        let sign = |x: f64| {
            [
                DVec3::new(x, 0.0, 0.0),
                DVec3::new(x, 8.0, 0.0),
                DVec3::new(x, 8.0, 8.0),
                DVec3::new(x, 0.0, 8.0),
            ]
        };
        let signs: Vec<[DVec3; 4]> = (0..10).map(|k| sign(100.0 * f64::from(k))).collect();
        let boxes = FenceBoxes::new(signs.iter().map(|s| &s[..]));
        let mut packet = RayPacket16::new();
        for lane in 0..10 {
            // From beside sign `lane` (50 units past it) along +x for 40 units: no sign reached.
            let x = 100.0 * lane as f32 + 50.0;
            packet.set(lane, [x, 4.0, 4.0], [1.0, 0.0, 0.0], 0.0, 40.0);
        }
        // Reaching sign 3 from behind it, and sign 7 from in front.
        packet.set(10, [280.0, 4.0, 4.0], [1.0, 0.0, 0.0], 0.0, 40.0);
        packet.set(11, [720.0, 4.0, 4.0], [-1.0, 0.0, 0.0], 0.0, 30.0);
        // No finite end: walked whatever the boxes say.
        packet.set(
            12,
            [5000.0, 5000.0, 5000.0],
            [0.0, 0.0, 1.0],
            0.0,
            f32::INFINITY,
        );
        assert_eq!(
            lanes_near_in_every_build(&boxes, &packet, 0x1fff),
            0b1_1100_0000_0000
        );
        let segments = packet.segment_boxes();
        assert_eq!(segments.unbounded, 1 << 12);
        assert_eq!(
            segments.meeting([-1e9; 3], [1e9; 3]),
            0x0fff,
            "empty boxes meet nothing"
        );
    }

    #[test]
    fn masks_tile_and_need_an_open_texel() {
        let mut pixels = vec![1u8; 16 * 16];
        pixels[0] = OPEN_TEXEL;
        let mip = |pixels: Vec<u8>| {
            MipTex::new(
                "{grate",
                16,
                16,
                [pixels, vec![0; 64], vec![0; 16], vec![0; 4]],
            )
        };
        let mask = TexelMask::of(&mip(pixels)).expect("one open texel");
        assert!(mask.is_open(0.5, 0.5));
        assert!(mask.is_open(16.5, -15.5), "the texture tiles");
        assert!(!mask.is_open(1.5, 0.5));
        assert_eq!(TexelMask::of(&mip(vec![1u8; 256])), None);
    }
}
