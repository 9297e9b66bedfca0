//! The Embree scene rays are traced against: every opaque face of the world
//! and of shadow-casting brush models, plus the sky faces as a separate
//! geometry so a ray can tell "reached the sky" from "hit a wall".
//! A `_shadowself` model gets a small scene of its own, which only rays
//! from that model's faces are tested against; the `_shadowworldonly` models
//! share one that only rays from the world's faces are. `_switchableshadow` models
//! get a scene per style, apart from the rest: what they block of style-0
//! light goes on their style ([`TraceScene::switchable_blocks16`]), but for
//! rays from their own faces (and those of models sharing their style), which
//! they shadow as fixed geometry, as ericw-tools does.
//! Fence faces are kept apart too, so light can pass their open texels
//! ([`crate::fence`]). Faces on light channels other than 1 (`_object_channel_mask` of brush
//! models and of the entities merged into the world) get a scene per mask: they block the rays
//! of the lights whose shadow channels share a bit with it ([`TraceScene::occluded16_by`]), and
//! the shared scene (the world, on channel 1) only those of lights with channel 1 among them.
//! With bounce or dirt on, the shared scene is built twice: sealed (Embree's robust mode, for the
//! rays of lights and suns) and not, for the many rays of which one slipping through a seam
//! costs little: bounced light's segments and dirt's rays.

use std::collections::HashMap;
use std::sync::Arc;

use glam::DVec3;

use crate::embree::{Device, RayPacket16, Scene, SceneBuilder, sys};
use crate::error::LightError;
use crate::faces::{FaceGeom, FaceKind};
use crate::fence::{Fences, TexelMask};
use crate::mesh::Mesh;

/// The face of a triangle that blocks light but is no face of the BSP (a faceless model's
/// solid, see [`crate::hull`]).
const NO_FACE: u32 = u32::MAX;

/// Sun rays are tested for blockers up to this fraction of their distance to the sky.
const SKY_HIT_SHORTEN: f32 = 1.0 - 1e-5;

/// The sky faces a sun shines through ([`TraceScene::sky_filter`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkyFilter {
    /// Every sky face.
    Any,
    /// Those of one texture (`_suntexture`), by its index among the sky's textures.
    Texture(u16),
}

/// A committed scene and the geometry id of its sky faces.
pub struct TraceScene {
    pub scene: Scene,
    /// `scene`'s faces again, built for speed rather than sealed seams, for bounced light's
    /// segments ([`TraceScene::occluded16_scattered`]) and dirt's rays
    /// ([`TraceScene::opaque_hits16`]); when asked for.
    unsealed: Option<Scene>,
    sky_geom: u32,
    /// The sky faces alone, to find where a sun ray meets the sky first.
    sky_only: Option<Scene>,
    /// `scene`'s faces without the sky, for what blocks a sun ray before it meets the sky
    /// (built for maps with suns and sky).
    opaque_only: Option<Scene>,
    /// Per triangle of `sky_only`, its texture's index in `sky_textures`.
    sky_texture_of: Vec<u16>,
    /// The names of the sky faces' textures.
    sky_textures: Vec<String>,
    /// The face of each opaque triangle (by primitive id).
    opaque_faces: Vec<u32>,
    /// Per `_shadowself` model (not already in `scene`): its own faces.
    own: HashMap<usize, Scene>,
    /// The faces of the `_shadowworldonly` models, which shadow the world's faces only.
    world_only: Option<Scene>,
    /// Per switchable shadow style, the faces of its models.
    switchable: Vec<(u8, Scene)>,
    /// Per switchable shadow model, the index in `switchable` of its style.
    own_switchable: HashMap<usize, usize>,
    /// The shadow-casting fence faces, whose open texels let light through.
    fences: Option<Fences>,
    /// Per light-channel mask other than 1, the faces on it.
    channels: Vec<(u32, Scene)>,
    /// Triangles in the scene (opaque + sky) and the `_shadowself` scenes.
    pub triangles: usize,
}

/// What blocks light besides the world's faces.
#[derive(Debug, Clone, Copy, Default)]
pub struct Casters<'a> {
    /// Per face index, a world face that casts no shadow (it may be empty).
    pub shadowless: &'a [bool],
    /// Brush models whose faces shadow everything (`_shadow 1`).
    pub models: &'a [usize],
    /// Brush models whose faces shadow only their own model (`_shadowself 1`).
    pub self_shadow_models: &'a [usize],
    /// Brush models whose faces shadow only the world's (`_shadowworldonly 1`).
    pub world_shadow_models: &'a [usize],
    /// Polygons in world space: the solid of shadow-casting models without faces.
    pub solids: &'a [Vec<DVec3>],
    /// Brush models whose shadow is switchable, and its style.
    pub switchable: &'a [(usize, u8)],
    /// Faces with a fence texture and the mask of its open texels: light passes those.
    pub fences: &'a [(usize, Arc<TexelMask>)],
    /// Per face, its light channels (empty: every face on channel 1): faces off channel 1
    /// cast shadows on the lights whose shadow channels share a bit with theirs.
    pub channels: &'a [u32],
}

impl TraceScene {
    /// Builds the scene from `faces`: world faces (but those `casters.shadowless` marks), faces
    /// of `casters.models` and the polygons `casters.solids`; each of
    /// `casters.self_shadow_models` that is not also in `casters.models` gets a scene of its own
    /// faces, and each switchable style one of its models' faces. Liquids are left out (they
    /// let light through). With `unsealed`, the shared scene is built a second time without
    /// Embree's robust mode, for bounced light's segments and dirt's rays; with `for_suns`, its
    /// opaque faces once more without the sky, for sun rays.
    ///
    /// # Errors
    /// The Embree error if building fails.
    pub fn build(
        device: &Device,
        faces: &[FaceGeom],
        casters: &Casters,
        unsealed: bool,
        for_suns: bool,
    ) -> Result<TraceScene, LightError> {
        let Casters {
            shadowless,
            models: shadow_models,
            self_shadow_models,
            world_shadow_models,
            solids,
            switchable,
            fences,
            channels,
        } = *casters;
        let channel_of = |f: &FaceGeom| channels.get(f.index).copied().filter(|&c| c != 1);
        let fence_masks: HashMap<usize, &Arc<TexelMask>> =
            fences.iter().map(|(face, mask)| (*face, mask)).collect();
        let fence_mask = |f: &FaceGeom| fence_masks.get(&f.index).map(|&mask| mask.clone());
        let casts = |f: &FaceGeom| {
            let world = f.model == 0 && !shadowless.get(f.index).copied().unwrap_or(false);
            world || shadow_models.contains(&f.model)
        };
        let switchable_style = |f: &FaceGeom| {
            switchable
                .iter()
                .find(|(m, _)| *m == f.model)
                .map(|&(_, s)| s)
        };
        let mut opaque =
            Mesh::with_room_for(faces.iter().filter(|f| f.kind == FaceKind::Lit && casts(f)));
        let mut fence_faces = Vec::new();
        let mut sky = Mesh::default();
        // The world's sky faces, numbered by face, for the sky-alone scene.
        let mut sky_faces: Vec<(&FaceGeom, u32)> = Vec::new();
        let mut own_meshes: HashMap<usize, Mesh> = HashMap::new();
        let mut world_only = Mesh::default();
        let mut switchable_meshes: Vec<(u8, Mesh)> = Vec::new();
        let mut channel_meshes: Vec<(u32, Mesh)> = Vec::new();
        for f in faces {
            if let (FaceKind::Lit, Some(mask)) = (f.kind, channel_of(f)) {
                match channel_meshes.iter_mut().find(|(m, _)| *m == mask) {
                    Some((_, mesh)) => mesh.add(f),
                    None => {
                        let mut mesh = Mesh::default();
                        mesh.add(f);
                        channel_meshes.push((mask, mesh));
                    }
                }
                continue;
            }
            if let (FaceKind::Lit, Some(style)) = (f.kind, switchable_style(f)) {
                crate::styles::entry(&mut switchable_meshes, style, Mesh::default).add(f);
                continue;
            }
            match f.kind {
                FaceKind::Lit if casts(f) => match fence_mask(f) {
                    Some(mask) => fence_faces.push((f, mask)),
                    None => opaque.add(f),
                },
                FaceKind::Lit if world_shadow_models.contains(&f.model) => world_only.add(f),
                FaceKind::Lit if self_shadow_models.contains(&f.model) => {
                    own_meshes.entry(f.model).or_default().add(f);
                }
                FaceKind::Sky if f.model == 0 => {
                    sky.add(f);
                    sky_faces.push((f, f.index as u32));
                }
                _ => {}
            }
        }
        for polygon in solids {
            opaque.add_polygon(polygon, NO_FACE);
        }
        let mut triangles = opaque.triangles.len() + sky.triangles.len();
        let fences = Fences::build(device, &fence_faces)?;
        let mut own = HashMap::with_capacity(own_meshes.len());
        for (model, mesh) in own_meshes {
            triangles += mesh.triangles.len();
            own.insert(model, mesh.commit(device)?);
        }
        triangles += world_only.triangles.len();
        let world_only = if world_only.triangles.is_empty() {
            None
        } else {
            Some(world_only.commit(device)?)
        };
        let mut switchable = Vec::with_capacity(switchable_meshes.len());
        for (style, mesh) in switchable_meshes {
            triangles += mesh.triangles.len();
            switchable.push((style, mesh.commit(device)?));
        }
        let mut channel_scenes = Vec::with_capacity(channel_meshes.len());
        for (mask, mesh) in channel_meshes {
            triangles += mesh.triangles.len();
            channel_scenes.push((mask, mesh.commit(device)?));
        }
        let own_switchable = casters
            .switchable
            .iter()
            .filter_map(|&(model, style)| {
                let k = switchable.iter().position(|(s, _)| *s == style)?;
                Some((model, k))
            })
            .collect();
        // The sky faces alone: thinned, none of the walls that stand on them being there.
        let sky_alone = Mesh::thinned(&sky_faces);
        let mut sky_textures: Vec<String> = Vec::new();
        let sky_texture_of = sky_alone
            .faces
            .iter()
            .map(|&f| {
                let name = faces.get(f as usize).map_or("", |f| f.texture.as_str());
                let at = sky_textures
                    .iter()
                    .position(|t| t.eq_ignore_ascii_case(name))
                    .unwrap_or_else(|| {
                        sky_textures.push(name.to_string());
                        sky_textures.len() - 1
                    });
                u16::try_from(at).unwrap_or(u16::MAX)
            })
            .collect();
        let sky_only = if sky.triangles.is_empty() {
            None
        } else {
            Some(sky_alone.commit(device)?)
        };
        let shared = || -> Result<(SceneBuilder, u32), LightError> {
            let mut builder = SceneBuilder::new(device)?;
            builder.add_triangle_mesh(&opaque.vertices, &opaque.triangles)?;
            let sky_geom = builder.add_triangle_mesh(&sky.vertices, &sky.triangles)?;
            Ok((builder, sky_geom))
        };
        let (builder, sky_geom) = shared()?;
        let opaque_only = if for_suns && sky_only.is_some() {
            Some(opaque.commit(device)?)
        } else {
            None
        };
        let unsealed = if unsealed {
            Some(shared()?.0.commit_unsealed()?)
        } else {
            None
        };
        Ok(TraceScene {
            scene: builder.commit()?,
            unsealed,
            sky_geom,
            sky_only,
            opaque_only,
            sky_texture_of,
            sky_textures,
            opaque_faces: opaque.faces,
            own,
            world_only,
            switchable,
            own_switchable,
            fences,
            channels: channel_scenes,
            triangles,
        })
    }

    /// The styles of switchable shadows, in the order [`TraceScene::switchable_blocks16`]
    /// numbers them.
    pub fn switchable_styles(&self) -> impl Iterator<Item = u8> + '_ {
        self.switchable.iter().map(|(s, _)| *s)
    }

    /// Some model casts a switchable shadow.
    pub fn has_switchable(&self) -> bool {
        !self.switchable.is_empty()
    }

    /// The shared faces for rays of which one slipping through a seam costs little: the
    /// unsealed build when there is one (its sky has the same geometry id).
    fn fast_scene(&self) -> &Scene {
        self.unsealed.as_ref().unwrap_or(&self.scene)
    }

    /// Lanes of `packet` (each up to its current `tfar`) that the models of switchable shadow
    /// number `k` block.
    pub fn switchable_blocks16(&self, packet: &mut RayPacket16, k: usize) -> u16 {
        self.switchable[k].1.occluded16(packet, true)
    }

    /// The number (as [`TraceScene::switchable_blocks16`] takes it) of the switchable shadow
    /// `model` is part of, whose models shadow `model`'s faces as fixed geometry.
    pub fn own_switchable(&self, model: usize) -> Option<usize> {
        self.own_switchable.get(&model).copied()
    }

    /// Lanes of `packet` any switchable shadow blocks: sunlight takes them as fixed shadows.
    fn any_switchable_blocks16(&self, packet: &mut RayPacket16) -> u16 {
        self.switchable
            .iter()
            .fold(0, |m, (_, scene)| m | scene.occluded16(packet, true))
    }

    /// Bit `i` set if lane `i` of `packet`, cast from a face of brush model
    /// `model`, is blocked (sky blocks too).
    pub fn occluded16(&self, packet: &mut RayPacket16, model: usize) -> u16 {
        self.occluded16_by(packet, model, 1)
    }

    /// [`TraceScene::occluded16`] for a packet whose lanes run in many directions from many
    /// origins (bounced light's segments from several reflecting faces): Embree is told they are
    /// incoherent, which traverses such packets faster (coherent packets, as a light's rays to
    /// one face, go faster the other way), and they go through the shared faces built without
    /// sealed seams when the scene has them: a segment that meets an edge exactly may pass
    /// between its triangles, giving one luxel a little of one emitter's bounced light that
    /// the sealed build would block.
    pub fn occluded16_scattered(&self, packet: &mut RayPacket16, model: usize) -> u16 {
        self.blocked16(self.fast_scene(), packet, model, 1, false)
    }

    /// [`TraceScene::occluded16`] for the rays of a light whose shadow channels are
    /// `shadow_channels`: the world and the faces on channel 1 block them when it has channel
    /// 1, the faces on other channels when it shares one of theirs.
    pub fn occluded16_by(
        &self,
        packet: &mut RayPacket16,
        model: usize,
        shadow_channels: u32,
    ) -> u16 {
        self.blocked16(&self.scene, packet, model, shadow_channels, true)
    }

    /// [`TraceScene::occluded16_by`], the shared faces being `shared` (`scene` or `unsealed`),
    /// queried `coherent` or not.
    fn blocked16(
        &self,
        shared: &Scene,
        packet: &mut RayPacket16,
        model: usize,
        shadow_channels: u32,
        coherent: bool,
    ) -> u16 {
        let mut blocked = 0;
        if shadow_channels & 1 != 0 {
            let opaque = shared.occluded16(packet, coherent);
            // Only the lanes the opaque faces let through can be blocked by a fence; Embree
            // has set the others' tfar to -inf, so the second query skips them too.
            blocked = opaque | self.fences_block16(packet, !opaque);
            blocked |= self.own_occluded16(packet, model);
        }
        self.channels_block16(packet, shadow_channels) | blocked
    }

    /// Lanes of `packet` that the faces on light channels other than 1 sharing a bit with
    /// `shadow_channels` block.
    fn channels_block16(&self, packet: &mut RayPacket16, shadow_channels: u32) -> u16 {
        self.channels
            .iter()
            .filter(|(mask, _)| mask & shadow_channels != 0)
            .fold(0, |m, (_, scene)| m | scene.occluded16(packet, true))
    }

    /// Of the active `lanes` of `packet`, those a fence face blocks at an opaque texel.
    fn fences_block16(&self, packet: &RayPacket16, lanes: u16) -> u16 {
        let lanes = lanes & packet.active_mask();
        match &self.fences {
            Some(f) if lanes != 0 => f.blocks16(packet, lanes),
            _ => 0,
        }
    }

    /// The scenes that shadow `model`'s faces beside the shared one: its own `_shadowself`
    /// scene, its switchable shadow's models, and for the world the world-only shadows.
    fn own_scenes(&self, model: usize) -> impl Iterator<Item = &Scene> {
        let world_only = self.world_only.as_ref().filter(|_| model == 0);
        let switchable = self.own_switchable(model).map(|k| &self.switchable[k].1);
        self.own
            .get(&model)
            .into_iter()
            .chain(switchable)
            .chain(world_only)
    }

    /// Lanes of `packet` (each up to its current `tfar`) that `model`'s own scenes block
    /// ([`TraceScene::own_scenes`]); 0 for a model without any.
    fn own_occluded16(&self, packet: &mut RayPacket16, model: usize) -> u16 {
        // Embree sets a blocked lane's tfar to -inf: each later query skips it.
        self.own_scenes(model)
            .fold(0, |m, scene| m | scene.occluded16(packet, true))
    }

    /// Which sky faces a sun shines through: all, or those of its `_suntexture` (`None`: the
    /// sky has no face of that texture, so the sun reaches nothing). Resolved once per sun,
    /// outside the loop over its rays.
    pub fn sky_filter(&self, texture: Option<&str>) -> Option<SkyFilter> {
        match texture {
            None => Some(SkyFilter::Any),
            Some(name) => self
                .sky_textures
                .iter()
                .position(|t| t.eq_ignore_ascii_case(name))
                .and_then(|at| u16::try_from(at).ok())
                .map(SkyFilter::Texture),
        }
    }

    /// Bit `i` set if lane `i` of `packet`, cast from a face of `model`,
    /// reaches a sky face `filter` lets through before anything else.
    /// First where each ray meets the sky (sky faces alone, a small scene),
    /// then whether anything blocks it before that: an occlusion query on
    /// the faces without the sky (whose slivers would only slow it),
    /// which stops at any hit, where one closest-hit query over everything
    /// must rule out every nearer surface.
    pub fn sees_sky16(&self, packet: &mut RayPacket16, model: usize, filter: SkyFilter) -> u16 {
        let Some(sky_only) = &self.sky_only else {
            return 0;
        };
        let hits = sky_only.first_hits16(packet, true);
        let through = |(geom, prim): (u32, u32)| {
            geom != sys::RTC_INVALID_GEOMETRY_ID
                && match filter {
                    SkyFilter::Any => true,
                    SkyFilter::Texture(t) => self.sky_texture_of.get(prim as usize) == Some(&t),
                }
        };
        let sky = (0..16)
            .filter(|&i| through(hits[i]))
            .fold(0, |m, i| m | (1 << i));
        // Just short of the sky hit, so the sky face itself does not block.
        packet.keep_shortened(sky, SKY_HIT_SHORTEN);
        let blockers = self.opaque_only.as_ref().unwrap_or(&self.scene);
        let opaque = blockers.occluded16(packet, true);
        let blocked = opaque | self.fences_block16(packet, !opaque);
        sky & !blocked
            & !self.own_occluded16(packet, model)
            & !self.any_switchable_blocks16(packet)
            & !self.channels_block16(packet, 1)
    }

    /// For each active lane of `packet`, cast from a face of `model`, the
    /// opaque face it meets first and the distance to it (`None`: it meets
    /// nothing, the sky, or `model`'s own `_shadowself` scene or switchable
    /// shadow first).
    pub fn first_faces16(
        &self,
        packet: &mut RayPacket16,
        model: usize,
    ) -> [Option<(usize, f32)>; 16] {
        let hits = self.scene.first_hits16(packet, false);
        let mut out = [None; 16];
        for (lane, (geom, prim)) in hits.iter().enumerate() {
            if *geom != self.sky_geom && *geom != sys::RTC_INVALID_GEOMETRY_ID {
                out[lane] = self
                    .opaque_faces
                    .get(*prim as usize)
                    .filter(|&&f| f != NO_FACE)
                    .map(|&f| (f as usize, packet.tfar(lane)));
            }
        }
        let own = self.own_occluded16(packet, model);
        for (lane, hit) in out.iter_mut().enumerate() {
            if own & (1 << lane) != 0 {
                *hit = None;
            }
        }
        out
    }

    /// For each active lane of `packet`, cast from a face of brush model `model` on light
    /// channels `channels`, the distance to the first surface if that is an opaque one (not
    /// sky), among what shares a light channel with the face (dirt: faces on other channels
    /// neither take it from the world nor give it). The shared faces are the unsealed ones when
    /// the scene has them: a dirt ray that meets an edge exactly may pass between its
    /// triangles, one ray of a sample's many.
    pub fn opaque_hits16(
        &self,
        packet: &mut RayPacket16,
        (model, channels): (usize, u32),
    ) -> [Option<f32>; 16] {
        let mut out = [None; 16];
        if channels & 1 != 0 {
            self.world_opaque_hits16(packet, model, &mut out);
        }
        // tfar ends at the nearest hit so far, so any hit here is nearer.
        for (_, scene) in self.channels.iter().filter(|(m, _)| m & channels != 0) {
            let ids = scene.first_hit_geom16(packet, true);
            for (lane, id) in ids.iter().enumerate() {
                if *id != sys::RTC_INVALID_GEOMETRY_ID {
                    out[lane] = Some(packet.tfar(lane));
                }
            }
        }
        out
    }

    /// [`TraceScene::opaque_hits16`] on channel 1: the shared scene and `model`'s own scenes.
    fn world_opaque_hits16(
        &self,
        packet: &mut RayPacket16,
        model: usize,
        out: &mut [Option<f32>; 16],
    ) {
        let ids = self.fast_scene().first_hit_geom16(packet, true);
        for (lane, id) in ids.iter().enumerate() {
            if *id != self.sky_geom && *id != sys::RTC_INVALID_GEOMETRY_ID {
                out[lane] = Some(packet.tfar(lane));
            }
        }
        for own in self.own_scenes(model) {
            // tfar ends at the nearest hit so far, so any hit here is nearer.
            let own_ids = own.first_hit_geom16(packet, true);
            for (lane, id) in own_ids.iter().enumerate() {
                if *id != sys::RTC_INVALID_GEOMETRY_ID {
                    out[lane] = Some(packet.tfar(lane));
                }
            }
        }
    }
}
