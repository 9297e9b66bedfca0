//! Faces: made from the portals where leaf contents change, textured from the brush side lying
//! on the portal, then merged (coplanar, same texinfo) and subdivided for lightmaps.

use crate::brush::{Brush, BrushKind, Side};
use crate::planes::{PlaneId, PlaneSet};
use crate::portals::{Portal, Portals};
use crate::texinfo::TextureRole;
use crate::tree::{
    Tree, TreeNode, VISBLOCKER, contents_priority, engine_contents, is_see_through,
    shows_faces_behind,
};
use glam::DVec3;
use quake_formats::bsp::contents;
use quake_formats::bsp::limits::MAX_SURFACE_EXTENT;
use quake_formats::extents::LightmapExtents;
use quake_formats::geom::DVec3Ext;
use quake_formats::geom::{ON_EPSILON, POINT_EPSILON, Plane, Split, Winding};
use std::collections::{HashMap, HashSet};
use std::rc::Rc;

/// A face of one model, before vertices and edges are shared.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ModelFace {
    /// The tree node whose plane the face lies on.
    pub node: u32,
    pub plane: PlaneId,
    /// Faces the back of the plane.
    pub back: bool,
    /// Map texinfo index.
    pub texinfo: u32,
    /// Clockwise seen from the side the face is looked at from.
    pub winding: Winding,
    /// Tree leaves whose marksurfaces list the face.
    pub leaves: Vec<u32>,
    /// Listed away from the leaf it is seen from (behind a fence, seen from the open leaves
    /// around it): those leaves' bounds must grow to hold it.
    pub stored: bool,
    /// The engine contents of the leaf the face is seen from. As in id's qbsp, faces seen from
    /// different contents (a water surface from above and from below) neither merge nor share
    /// edges: software renderers (WinQuake's edge list) draw such faces wrongly.
    pub seen_from: i32,
    /// The compiler contents of the leaf the face is painted from (what its brush is made of:
    /// see [`crate::weld::WeldClass`]).
    pub painted_from: i32,
}

impl ModelFace {
    /// The normal of the side the face is seen from.
    pub fn normal(&self, planes: &PlaneSet) -> DVec3 {
        let n = planes.get(self.plane).normal;
        if self.back { -n } else { n }
    }
}

/// What face making needs to know about a map texinfo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FaceTexInfo {
    pub vecs: [[f64; 4]; 2],
    pub role: TextureRole,
    /// Written with `TEX_SPECIAL` ([`crate::gather::MapTexInfo::is_special`]).
    pub special: bool,
}

/// Face counts for the summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct FaceStats {
    /// Faces made from portals, before merging.
    pub from_portals: usize,
    /// Portal faces whose texture had to be guessed (no brush side of the leaf on the portal:
    /// the nearest side's).
    pub untextured: usize,
    /// Faces left after merging.
    pub after_merge: usize,
    /// Merged faces whose texture met them edge-on, given Quake's projection for their plane.
    pub squared_up: usize,
    /// Faces left after subdivision.
    pub after_subdivide: usize,
}

/// The least [`projection_squareness`] a face keeps its texture's projection with: below it
/// (closer than about 6 degrees to edge-on) the texture is smeared tenfold or more, which no
/// mapper means, and at 0 light tools cannot map texture space back onto the face at all
/// (ericw-tools' light stops on such a face).
pub const MIN_SQUARENESS: f64 = 0.1;

/// How squarely a texture projects onto a face with unit `normal`: the |cosine| of the angle
/// between it and the normal of the texture's s/t plane, 0 when the texture meets the face
/// edge-on (floor axes on a wall) or an axis is zero.
pub fn projection_squareness(vecs: &[[f64; 4]; 2], normal: DVec3) -> f64 {
    let axis = |row: &[f64; 4]| DVec3::new(row[0], row[1], row[2]);
    axis(&vecs[0])
        .cross(axis(&vecs[1]))
        .normalized()
        .map_or(0.0, |t| t.dot(normal).abs())
}

/// Whether a face on the boundary of leaf `owner`, drawn seen from inside it when `mirrored`, is
/// seen from the leaf of contents `viewer` on its other side (`own_side` false) or from inside
/// the owner.
fn seen_from(mirrored: bool, viewer: i32, own_side: bool) -> bool {
    if own_side {
        mirrored
    } else {
        shows_faces_behind(viewer)
    }
}

/// Whether a brush's faces are drawn seen from inside it: as its `_mirrorinside` says, else (as
/// in ericw-tools) for liquids and vis blockers, which players look out of, and not for solid,
/// fence or illusionary brushes.
fn brush_mirrors_inside(b: &Brush) -> bool {
    b.mirror_inside.unwrap_or(mirrors_by_default(b.contents))
}

fn mirrors_by_default(c: i32) -> bool {
    matches!(
        c,
        contents::WATER | contents::SLIME | contents::LAVA | VISBLOCKER
    )
}

/// Whether the faces of a leaf's brushes are drawn seen from inside it, for a face no brush side
/// of the leaf lies on: as its brushes of its contents say ([`brush_mirrors_inside`]).
fn mirrors_inside(leaf: &TreeNode) -> bool {
    leaf.brushes
        .iter()
        .filter(|b| b.contents == leaf.contents)
        .find_map(|b| b.mirror_inside)
        .unwrap_or(mirrors_by_default(leaf.contents))
}

/// A part of a portal face: its winding, texinfo and whether it is drawn seen from inside its
/// owner too.
struct Painted {
    winding: Winding,
    texinfo: u32,
    mirrored: bool,
}

/// How much a brush side's plane turned away from a face's counts against it, in units of
/// distance per unit of (1 - cosine): 5 degrees weigh about as much as 4 units.
const TURN_WEIGHT: f64 = 1000.0;

/// Where the texture of a face on a portal is looked for.
struct TextureSearch<'a> {
    tree: &'a Tree,
    portals: &'a Portals,
    planes: &'a PlaneSet,
}

impl TextureSearch<'_> {
    /// The brushes of leaf `owner` whose sides texture its faces: those of the leaf's own
    /// contents, else every textured one; in map order.
    fn own_brushes(&self, owner: u32) -> Vec<&Brush> {
        let leaf = &self.tree.nodes[owner as usize];
        let brushes: Vec<&Brush> = leaf
            .brushes
            .iter()
            .filter(|b| b.contents == leaf.contents)
            .collect();
        if brushes.is_empty() {
            leaf.brushes.iter().filter(|b| is_textured(b)).collect()
        } else {
            brushes
        }
    }

    /// `winding`, a face on `plane` looking out of leaf `owner` (`flipped` as in
    /// [`crate::brush::Side`]), cut where the sides of the leaf's brushes lying on it change,
    /// each part with its texinfo and mirroring from its side's brush: where sides overlap, the
    /// brush latest in the map wins (a button set flush into a floor shows its own face), as in
    /// id's qbsp and ericw-tools, where later brushes clip earlier ones. Parts no side covers
    /// take [`TextureSearch::texinfo`]'s.
    fn paint(&self, owner: u32, plane: PlaneId, flipped: bool, winding: &Winding) -> Vec<Painted> {
        let normal = self.outward(plane, flipped).normal;
        // Latest first: fragments keep their map order.
        let sides: Vec<(&Brush, &Side)> = self
            .own_brushes(owner)
            .into_iter()
            .rev()
            .flat_map(|b| b.sides.iter().map(move |s| (b, s)))
            .filter(|(_, s)| s.texinfo.is_some() && s.plane == plane && s.flipped == flipped)
            .collect();
        let look = |(b, s): &(&Brush, &Side)| (s.texinfo, brush_mirrors_inside(b));
        let mut out = Vec::new();
        let mut rest = vec![winding.clone()];
        if sides.windows(2).any(|w| look(&w[0]) != look(&w[1])) {
            for side in &sides {
                let (texinfo, mirrored) = look(side);
                let mut outside = Vec::new();
                for piece in rest {
                    let inside = split_by_polygon(piece, &side.1.winding, normal, &mut outside);
                    out.extend(inside.zip(texinfo).map(|(winding, texinfo)| Painted {
                        winding,
                        texinfo,
                        mirrored,
                    }));
                }
                rest = outside;
            }
        }
        let mirrored = sides.first().map_or_else(
            || mirrors_inside(&self.tree.nodes[owner as usize]),
            |s| look(s).1,
        );
        for piece in rest {
            if let Some(texinfo) = self.texinfo(owner, plane, flipped, piece.center()) {
                out.push(Painted {
                    winding: piece,
                    texinfo,
                    mirrored,
                });
            }
        }
        out
    }

    /// The texinfo of the side of leaf `owner`'s brushes on `plane` facing out of it (`flipped`
    /// as in [`crate::brush::Side`]), brushes of the leaf's own contents first, the latest in the
    /// map first; failing that,
    /// of the side whose outward plane lies closest to the face (centred at `center`) among
    /// the brushes of `owner` and of the leaves of its contents next to it; `None` when
    /// `owner`'s brushes have no textured side. The tree leaves out a side within the epsilon of
    /// a node plane or cutting off a sliver, so a leaf may have no side on its face; in a crack
    /// filled whole the wall's own side is in the next leaf.
    fn texinfo(&self, owner: u32, plane: PlaneId, flipped: bool, center: DVec3) -> Option<u32> {
        let leaf = &self.tree.nodes[owner as usize];
        let own = textured_sides(self.own_brushes(owner).into_iter().rev());
        if let Some(s) = own
            .iter()
            .find(|s| s.plane == plane && s.flipped == flipped)
            .or_else(|| own.iter().find(|s| s.plane == plane))
        {
            return s.texinfo;
        }
        if own.is_empty() {
            return None;
        }
        let next_to = self.portals.leaf_portals[owner as usize]
            .iter()
            .map(|&p| self.portals.other(p, owner))
            .filter(|&n| n != self.portals.outside)
            .map(|n| &self.tree.nodes[n as usize])
            .filter(|n| n.contents == leaf.contents)
            .flat_map(|n| n.brushes.iter().filter(|b| is_textured(b)));
        let face = self.outward(plane, flipped);
        let gap = |s: &Side| {
            let o = self.outward(s.plane, s.flipped);
            o.distance(center).abs() + TURN_WEIGHT * (1.0 - o.normal.dot(face.normal))
        };
        own.into_iter()
            .chain(textured_sides(next_to))
            .min_by(|a, b| gap(a).total_cmp(&gap(b)))
            .and_then(|s| s.texinfo)
    }

    fn outward(&self, id: PlaneId, flipped: bool) -> Plane {
        let p = self.planes.get(id);
        if flipped { p.flipped() } else { *p }
    }
}

fn is_textured(b: &Brush) -> bool {
    b.kind != BrushKind::Hint
}

/// The sides of `brushes` that carry a map face's texture.
fn textured_sides<'a>(brushes: impl IntoIterator<Item = &'a Brush>) -> Vec<&'a Side> {
    brushes
        .into_iter()
        .flat_map(|b| &b.sides)
        .filter(|s| s.texinfo.is_some())
        .collect()
}

/// Split `piece`, a polygon on the plane of the convex `polygon` (both facing `normal`), into
/// the part inside `polygon` (returned) and the parts outside it (pushed to `outside`).
fn split_by_polygon(
    piece: Winding,
    polygon: &Winding,
    normal: DVec3,
    outside: &mut Vec<Winding>,
) -> Option<Winding> {
    let center = polygon.center();
    let n = polygon.len();
    let mut inside = piece;
    for i in 0..n {
        let (a, b) = (polygon.points[i], polygon.points[(i + 1) % n]);
        let Some(across) = normal.cross(b - a).normalized() else {
            continue;
        };
        // Facing out of the polygon, whichever way it winds.
        let across = if across.dot(center - a) > 0.0 {
            -across
        } else {
            across
        };
        match inside.split(&Plane::new(across, across.dot(a))) {
            Split::Front(w) => {
                outside.push(w);
                return None;
            }
            Split::Both { front, back } => {
                outside.push(front);
                inside = back;
            }
            Split::Back(w) | Split::On { winding: w, .. } => inside = w,
        }
    }
    Some(inside)
}

/// Where faces seen from each leaf are listed. A face seen from a fence or a detail wall (solid
/// leaves, which engines never draw from) is listed in the open leaves the connected fence or
/// wall leaves border, flooding through them (a fence cut into several leaves may hold a face
/// only one of them sees, far from any open leaf), as ericw-tools' `FixupDetailFence` does.
struct ViewingLeaves<'a> {
    tree: &'a Tree,
    portals: &'a Portals,
    /// The open leaves around each flooded solid viewer.
    around: HashMap<u32, Rc<Vec<u32>>>,
}

impl ViewingLeaves<'_> {
    fn solid_viewer(&self, leaf: u32) -> bool {
        leaf != self.portals.outside
            && engine_contents(self.tree.nodes[leaf as usize].contents) == contents::SOLID
    }

    /// The leaves a face seen from `viewer` is listed in, and whether they are open leaves
    /// around a solid viewer rather than the viewer itself.
    fn of(&mut self, viewer: u32) -> (Rc<Vec<u32>>, bool) {
        if !self.solid_viewer(viewer) {
            return (Rc::new(vec![viewer]), false);
        }
        if let Some(open) = self.around.get(&viewer) {
            return (open.clone(), !open.contains(&viewer));
        }
        let mut flooded = vec![viewer];
        let mut seen = HashSet::from([viewer]);
        let mut open = Vec::new();
        let mut i = 0;
        while i < flooded.len() {
            let leaf = flooded[i];
            i += 1;
            for &p in &self.portals.leaf_portals[leaf as usize] {
                let other = self.portals.other(p, leaf);
                if other == self.portals.outside || !seen.insert(other) {
                    continue;
                }
                let c = self.tree.nodes[other as usize].contents;
                if self.solid_viewer(other) && c != contents::SOLID {
                    flooded.push(other);
                } else if is_see_through(c) {
                    open.push(other);
                }
            }
        }
        open.sort_unstable();
        // Nothing open around it: the face stays with its viewer, seen by nobody.
        let open = Rc::new(if open.is_empty() { vec![viewer] } else { open });
        for leaf in flooded {
            self.around.insert(leaf, open.clone());
        }
        (open.clone(), !open.contains(&viewer))
    }
}

/// Faces on every portal between leaves of different contents, seen from each side that can see
/// them, textured by the stronger side's brushes; and on portals between leaves of one contents
/// whose brushes keep their faces there ([`keeps_faces_between`]).
pub(crate) fn faces_from_portals(
    tree: &Tree,
    portals: &Portals,
    planes: &PlaneSet,
    texinfos: &[FaceTexInfo],
    stats: &mut FaceStats,
) -> Vec<ModelFace> {
    let mut maker = FaceMaker {
        search: TextureSearch {
            tree,
            portals,
            planes,
        },
        viewing: ViewingLeaves {
            tree,
            portals,
            around: HashMap::new(),
        },
        texinfos,
        stats,
        faces: Vec::new(),
    };
    for p in &portals.portals {
        let [a, b] = p.nodes;
        if a == portals.outside || b == portals.outside {
            continue;
        }
        let (ca, cb) = (
            tree.nodes[a as usize].contents,
            tree.nodes[b as usize].contents,
        );
        if ca == cb && keeps_faces_between(tree, a, b) {
            // Each leaf's own faces on the portal, looking into the other.
            for owner_is_front in [true, false] {
                maker.faces_on(p, owner_is_front, PortalFace::Kept);
            }
        } else if contents_priority(ca) != contents_priority(cb) {
            maker.faces_on(
                p,
                contents_priority(ca) > contents_priority(cb),
                PortalFace::Boundary,
            );
        }
    }
    maker.faces
}

/// Whether the faces between leaves `a` and `b`, of one contents, are kept: a brush of that
/// contents in either has `_noclipfaces`.
fn keeps_faces_between(tree: &Tree, a: u32, b: u32) -> bool {
    [a, b].into_iter().any(|leaf| {
        let leaf = &tree.nodes[leaf as usize];
        leaf.brushes
            .iter()
            .any(|br| br.contents == leaf.contents && br.no_clip_faces)
    })
}

/// Whether any of `brushes` has a map face on `plane` facing out of it as `flipped` says.
fn side_on<'a>(
    brushes: impl IntoIterator<Item = &'a Brush>,
    plane: PlaneId,
    flipped: bool,
) -> bool {
    brushes
        .into_iter()
        .flat_map(|b| &b.sides)
        .any(|s| s.plane == plane && s.flipped == flipped && s.texinfo.is_some())
}

/// Why a portal has faces.
#[derive(Clone, Copy, PartialEq)]
enum PortalFace {
    /// Contents change across it: its face is textured from the nearest side when no side of
    /// its owner lies on it, and the other leaf sees it only if faces behind it show
    /// ([`seen_from`]).
    Boundary,
    /// `_noclipfaces` keeps the faces between leaves of one contents: made only where a side of
    /// the owner lies on the portal (else every split inside a brush would become a face), seen
    /// from the other leaf whatever it is (the mapper asked for them).
    Kept,
}

/// Makes the faces of one model's portals.
struct FaceMaker<'a> {
    search: TextureSearch<'a>,
    viewing: ViewingLeaves<'a>,
    texinfos: &'a [FaceTexInfo],
    stats: &'a mut FaceStats,
    faces: Vec<ModelFace>,
}

impl FaceMaker<'_> {
    /// The faces on portal `p` looking out of its leaf in front of the plane (`owner_is_front`)
    /// or behind it, painted from that leaf's brushes, each seen from the other leaf and, when
    /// mirrored, from the owner, as `why` allows.
    fn faces_on(&mut self, p: &Portal, owner_is_front: bool, why: PortalFace) {
        let (Some(node), Some(plane)) = (p.on_node, p.plane_id) else {
            return;
        };
        let tree = self.search.tree;
        let [a, b] = p.nodes;
        let owner = if owner_is_front { a } else { b };
        // The owner's side looks out of it: backwards along the plane when it is in front.
        let exact = match why {
            PortalFace::Boundary => {
                side_on(&tree.nodes[owner as usize].brushes, plane, owner_is_front)
            }
            PortalFace::Kept => side_on(self.search.own_brushes(owner), plane, owner_is_front),
        };
        if !exact && why == PortalFace::Kept {
            return;
        }
        for part in self.search.paint(owner, plane, owner_is_front, &p.winding) {
            let Painted {
                winding,
                texinfo,
                mirrored,
            } = part;
            if !self.texinfos[texinfo as usize].role.is_drawn() {
                continue;
            }
            for (viewer, front) in [(a, true), (b, false)] {
                let viewer_contents = tree.nodes[viewer as usize].contents;
                let own_side = viewer == owner;
                let asked = why == PortalFace::Kept && !own_side;
                if !(asked || seen_from(mirrored, viewer_contents, own_side)) {
                    continue;
                }
                let (leaves, stored) = self.viewing.of(viewer);
                // A face behind a fence is seen from the open leaves around it.
                let seen_from = leaves
                    .iter()
                    .map(|&l| engine_contents(tree.nodes[l as usize].contents))
                    .find(|&c| c != contents::SOLID)
                    .unwrap_or(engine_contents(viewer_contents));
                self.stats.from_portals += 1;
                self.stats.untextured += usize::from(!exact);
                self.faces.push(ModelFace {
                    node,
                    plane,
                    back: !front,
                    texinfo,
                    winding: if front {
                        winding.clone()
                    } else {
                        winding.reversed()
                    },
                    leaves: leaves.to_vec(),
                    stored,
                    seen_from,
                    painted_from: tree.nodes[owner as usize].contents,
                });
            }
        }
    }
}

/// The two polygons joined along a shared edge, if the result is convex.
fn try_merge(a: &Winding, b: &Winding, normal: DVec3) -> Option<Winding> {
    let (n, m) = (a.len(), b.len());
    let mut shared = None;
    'outer: for i in 0..n {
        let (p1, p2) = (a.points[i], a.points[(i + 1) % n]);
        for j in 0..m {
            if b.points[j].near(p2, POINT_EPSILON) && b.points[(j + 1) % m].near(p1, POINT_EPSILON)
            {
                shared = Some((i, j));
                break 'outer;
            }
        }
    }
    let (i, j) = shared?;
    let mut points: Vec<DVec3> = (1..=n).map(|k| a.points[(i + k) % n]).collect();
    points.extend((2..m).map(|k| b.points[(j + k) % m]));
    simplify_convex(points, normal)
}

/// Drop collinear points; `None` if the polygon is not convex (clockwise about `normal`).
fn simplify_convex(mut points: Vec<DVec3>, normal: DVec3) -> Option<Winding> {
    let mut k = 0;
    while k < points.len() && points.len() >= 3 {
        let len = points.len();
        let prev = points[(k + len - 1) % len];
        let cur = points[k];
        let next = points[(k + 1) % len];
        let Some(dir) = (next - prev).normalized() else {
            points.remove(k);
            continue;
        };
        let off = (cur - prev) - dir * (cur - prev).dot(dir);
        if off.length() < ON_EPSILON {
            points.remove(k);
            continue;
        }
        if (cur - prev).cross(next - cur).dot(normal) > 0.0 {
            return None;
        }
        k += 1;
    }
    (points.len() >= 3).then(|| Winding::new(points))
}

/// Merge faces that share a node, side, texinfo and the contents they are seen from wherever
/// the union stays convex.
pub(crate) fn merge_faces(
    mut faces: Vec<ModelFace>,
    plane_of: impl Fn(&ModelFace) -> Plane,
) -> Vec<ModelFace> {
    let key = |f: &ModelFace| (f.node, f.back, f.texinfo, f.seen_from);
    faces.sort_by_key(key);
    let mut out: Vec<ModelFace> = Vec::with_capacity(faces.len());
    let mut start = 0;
    while start < faces.len() {
        let group_key = key(&faces[start]);
        let end = start
            + faces[start..]
                .iter()
                .take_while(|f| key(f) == group_key)
                .count();
        let mut group: Vec<ModelFace> = faces[start..end].to_vec();
        let normal = plane_of(&group[0]).normal * if group_key.1 { -1.0 } else { 1.0 };
        loop {
            let mut merged_any = false;
            let mut i = 0;
            while i < group.len() {
                let mut j = i + 1;
                while j < group.len() {
                    let touching = group[i]
                        .winding
                        .bounds()
                        .intersects(&group[j].winding.bounds());
                    if touching
                        && let Some(w) = try_merge(&group[i].winding, &group[j].winding, normal)
                    {
                        let other = group.remove(j);
                        group[i].winding = w;
                        group[i].leaves.extend(other.leaves);
                        group[i].leaves.sort_unstable();
                        group[i].leaves.dedup();
                        group[i].stored |= other.stored;
                        merged_any = true;
                        j = i + 1;
                    } else {
                        j += 1;
                    }
                }
                i += 1;
            }
            if !merged_any {
                break;
            }
        }
        out.extend(group);
        start = end;
    }
    out
}

fn f32_vecs(vecs: &[[f64; 4]; 2]) -> [[f32; 4]; 2] {
    vecs.map(|row| row.map(|c| c as f32))
}

/// Lightmap extents of a winding as engines will compute them from the written file.
pub(crate) fn winding_extents(w: &Winding, vecs: &[[f64; 4]; 2]) -> LightmapExtents {
    let points: Vec<[f32; 3]> = w.points.iter().map(|p| p.as_vec3().to_array()).collect();
    LightmapExtents::from_points(&points, &f32_vecs(vecs))
}

/// Cut a lit face so each piece spans at most `size` texels along s and t, and its lightmap
/// extents stay within the engine limit.
pub(crate) fn subdivide(w: Winding, vecs: &[[f64; 4]; 2], size: f64, out: &mut Vec<Winding>) {
    let within = |w: &Winding| {
        let e = winding_extents(w, vecs);
        e.extents[0] <= MAX_SURFACE_EXTENT && e.extents[1] <= MAX_SURFACE_EXTENT
    };
    let mut pending = vec![(w, size)];
    let mut pieces = Vec::new();
    while let Some((w, size)) = pending.pop() {
        match cut_once(&w, vecs, size) {
            Some((back, front)) => {
                pending.push((front, size));
                pending.push((back, size));
            }
            // Rounding pushed the extents over the limit: cut this piece smaller.
            None if !within(&w) && size > 32.0 => pending.push((w, size - 16.0)),
            None => pieces.push(w),
        }
    }
    out.extend(pieces);
}

/// `face` as it is written: cut by [`subdivide`] when lit, whole when special (sky, liquids).
pub(crate) fn cut_for_lightmaps(
    face: ModelFace,
    info: &FaceTexInfo,
    size: f64,
    out: &mut Vec<ModelFace>,
) {
    // A size of 0 asks for no subdivision at all (ericw-tools' `-subdivide 0`).
    if info.special || size <= 0.0 {
        out.push(face);
        return;
    }
    let mut pieces = Vec::new();
    subdivide(face.winding.clone(), &info.vecs, size, &mut pieces);
    out.extend(pieces.into_iter().map(|winding| ModelFace {
        winding,
        ..face.clone()
    }));
}

/// One cut along s or t, `size - 16` texels past the minimum (leaving room for the 16-texel
/// grid rounding), or `None` when the winding is small enough.
fn cut_once(w: &Winding, vecs: &[[f64; 4]; 2], size: f64) -> Option<(Winding, Winding)> {
    for row in vecs {
        let axis = DVec3::new(row[0], row[1], row[2]);
        let len = axis.length();
        if len == 0.0 {
            continue;
        }
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in &w.points {
            let s = p.dot(axis);
            lo = lo.min(s);
            hi = hi.max(s);
        }
        if hi - lo <= size {
            continue;
        }
        let plane = Plane::new(axis / len, (lo + size - 16.0) / len);
        if let Split::Both { front, back } = w.split(&plane) {
            return Some((back, front));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, size: f64) -> Winding {
        // Clockwise seen from +Z.
        Winding::new(vec![
            DVec3::new(x0, y0, 0.0),
            DVec3::new(x0, y0 + size, 0.0),
            DVec3::new(x0 + size, y0 + size, 0.0),
            DVec3::new(x0 + size, y0, 0.0),
        ])
    }

    const UP: DVec3 = DVec3::new(0.0, 0.0, 1.0);

    #[test]
    fn adjacent_squares_merge_into_a_rectangle() {
        let w = try_merge(&square(0.0, 0.0, 64.0), &square(64.0, 0.0, 64.0), UP).expect("merge");
        assert_eq!(w.len(), 4);
        assert!((w.area() - 2.0 * 64.0 * 64.0).abs() < 1e-9);
    }

    #[test]
    fn l_shapes_do_not_merge() {
        let big = square(0.0, 0.0, 64.0);
        let small = Winding::new(vec![
            DVec3::new(64.0, 0.0, 0.0),
            DVec3::new(64.0, 32.0, 0.0),
            DVec3::new(96.0, 32.0, 0.0),
            DVec3::new(96.0, 0.0, 0.0),
        ]);
        // They share only part of an edge: no common edge, no merge.
        assert!(try_merge(&big, &small, UP).is_none());
    }

    #[test]
    fn squareness_of_projections() {
        let floor = [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]];
        let wall = DVec3::new(0.0, -1.0, 0.0);
        assert_eq!(projection_squareness(&floor, UP), 1.0);
        assert_eq!(projection_squareness(&floor, -UP), 1.0);
        // Floor axes on a wall: the texture meets it edge-on.
        assert_eq!(projection_squareness(&floor, wall), 0.0);
        let zero_axis = [[1.0, 0.0, 0.0, 0.0], [0.0; 4]];
        assert_eq!(projection_squareness(&zero_axis, UP), 0.0);
        // Scale does not matter, only the angle.
        let scaled = [[0.25, 0.0, 0.0, 7.0], [0.0, -4.0, 0.0, 3.0]];
        assert_eq!(projection_squareness(&scaled, UP), 1.0);
        let tilted = DVec3::new(0.0, 0.6, 0.8);
        assert!((projection_squareness(&floor, tilted) - 0.8).abs() < 1e-12);
    }

    #[test]
    fn subdivision_keeps_extents_within_limits() {
        let vecs = [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]];
        let mut out = Vec::new();
        subdivide(square(-8.0, 3.0, 1000.0), &vecs, 240.0, &mut out);
        assert!(out.len() >= 25);
        let area: f64 = out.iter().map(Winding::area).sum();
        assert!((area - 1000.0 * 1000.0).abs() < 1e-3);
        for w in &out {
            let e = winding_extents(w, &vecs);
            assert!(e.extents[0] <= MAX_SURFACE_EXTENT && e.extents[1] <= MAX_SURFACE_EXTENT);
        }
        // Scaled textures are cut in texture space.
        let mut out = Vec::new();
        subdivide(
            square(0.0, 0.0, 128.0),
            &[[4.0, 0.0, 0.0, 0.0], [0.0, -4.0, 0.0, 0.0]],
            240.0,
            &mut out,
        );
        assert!(out.len() >= 9);
    }

    /// Regression: a piece whose rounded extents overflowed shrank the cut size for every piece
    /// and face after it, cutting later faces into slivers.
    #[test]
    fn shrinking_one_piece_leaves_the_others_alone() {
        let vecs = [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]];
        let strip = Winding::new(vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 16.0, 0.0),
            DVec3::new(4000.0, 16.0, 0.0),
            DVec3::new(4000.0, 0.0, 0.0),
        ]);
        let alone = |w: &Winding, size: f64| {
            let mut out = Vec::new();
            subdivide(w.clone(), &vecs, size, &mut out);
            out
        };
        // 300 texels is more than the engine allows, so every piece takes the shrinking path.
        let big = alone(&strip, 300.0);
        assert!(big.len() <= 2 * (4000 / 224 + 1), "{} pieces", big.len());
        for w in &big {
            let e = winding_extents(w, &vecs);
            assert!(e.extents[0] <= MAX_SURFACE_EXTENT && e.extents[1] <= MAX_SURFACE_EXTENT);
        }
        // A face cut after it is cut as if alone.
        let mut out = Vec::new();
        subdivide(strip.clone(), &vecs, 300.0, &mut out);
        let before = out.len();
        subdivide(square(0.0, 0.0, 1000.0), &vecs, 240.0, &mut out);
        assert_eq!(out[before..], alone(&square(0.0, 0.0, 1000.0), 240.0)[..]);
    }
}
