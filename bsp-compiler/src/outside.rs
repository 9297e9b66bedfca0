//! Outside filling: flood from the void through open portals; if that reaches a point entity the
//! map leaks (report it with a path to the void), otherwise every flooded leaf becomes solid.
//! Then, as ericw-tools does by default, the space no point entity reaches (a closed room, the
//! inside of a closed box) is filled too (`fill_unreached`).
//!
//! The flood runs over the structural leaves (vis clusters) with their structural contents:
//! detail brushes never seal a map, as in ericw-tools. An entity lying on a brush face (within
//! `ON_EPSILON` of a node plane, between a sealing cluster and an open one) is placed on the
//! sealing side in hull 0 (`OnPlane`): a light set on the outer face of a ceiling does not leak.

use crate::leak::{LeakReport, MapBrushRef};
use crate::planes::PlaneSet;
use crate::portals::Portals;
use crate::tree::{DETAIL_WALL, Tree, TreeNode, VisibleSides, engine_contents, is_opaque};
use crate::warnings::Warning;
use glam::DVec3;
use quake_formats::bsp::contents;

use std::cmp::Ordering;
use std::collections::{BinaryHeap, VecDeque};

/// A point entity that marks open space.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Occupant {
    pub entity: usize,
    pub classname: String,
    pub origin: DVec3,
    /// The line of the `.map` where the entity starts.
    pub line: usize,
}

/// A map open to the void: the first entity the flood from outside reaches, and how.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Leak {
    pub occupant: Occupant,
    /// From the entity through portal centres to the outside box (what the `.pts` file holds).
    pub pointfile: Vec<DVec3>,
    /// The sealing brush faces beside the last place the path passes any (nearest first, at most
    /// [`EXIT_FACES`]): where it leaves the map, and where the mapper looks for the hole. Empty
    /// when the entity stands beyond every brush.
    pub exit: Vec<ExitFace>,
    /// The entity stands beyond the box around every brush of the map: it is what to move.
    pub beyond_brushes: bool,
}

/// How many brush faces a leak names.
pub(crate) const EXIT_FACES: usize = 3;

/// A brush face beside a leak's path.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ExitFace {
    /// [`crate::brush::Brush::source`] of the brush.
    pub brush: u32,
    /// The face's texinfo (`None` for a face the compiler made).
    pub texinfo: Option<u32>,
    /// The centre of the part of the face the path's leaf touches.
    pub point: DVec3,
}

impl Leak {
    /// The leak named for the mapper: `brush` finds a [`crate::brush::Brush::source`]'s map
    /// brush, `texture` a texinfo's texture name.
    pub fn report(
        &self,
        brush: impl Fn(u32) -> Option<MapBrushRef>,
        texture: impl Fn(u32) -> String,
    ) -> LeakReport {
        let o = &self.occupant;
        LeakReport {
            entity: o.entity,
            classname: o.classname.clone(),
            origin: o.origin,
            line: o.line,
            pointfile: self.pointfile.clone(),
            exit: self
                .exit
                .iter()
                .filter_map(|f| {
                    let name = f.texinfo.map(&texture).unwrap_or_default();
                    Some((brush(f.brush)?, name, f.point))
                })
                .collect(),
            beyond_brushes: self.beyond_brushes,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum FillOutcome {
    /// The outside was filled; this many leaves became solid.
    Sealed {
        filled: usize,
    },
    Leaked(Leak),
    /// No entity in open space: nothing can be told inside from outside.
    NoOccupants,
}

/// Which side an entity lying on a node plane (within [`quake_formats::geom::ON_EPSILON`]) is
/// placed on, when one side seals the map and the other is open.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum OnPlane {
    /// The sealing side: hull 0, where an entity standing exactly on a brush face of the map's
    /// outside (a light on a ceiling's top) must not leak.
    Sealing,
    /// The open side: the clip hulls, where brushes are grown and an entity near a wall often
    /// touches one; there an occupant only keeps a hull from being filled.
    Open,
}

/// Where a point entity sits for the flood.
enum Placement {
    /// In open space: the flood must not reach this cluster.
    Open(u32),
    /// On a face between open space and a sealing brush, placed on the sealing side.
    OnSealingFace,
    /// Inside sealing brushes.
    Sealed,
}

fn place(
    tree: &Tree,
    planes: &PlaneSet,
    origin: DVec3,
    on_plane: OnPlane,
    contents_of: impl Fn(u32) -> i32,
) -> Placement {
    let clusters = tree.clusters_touching(planes, origin);
    let sealing = |c: &u32| is_opaque(contents_of(*c));
    match clusters.iter().find(|c| !sealing(c)) {
        None => Placement::Sealed,
        Some(_) if on_plane == OnPlane::Sealing && clusters.iter().any(sealing) => {
            Placement::OnSealingFace
        }
        Some(&c) => Placement::Open(c),
    }
}

/// Flood `tree` from the outside and fill it unless an occupant is reached. `portals` are its
/// cluster portals ([`crate::portals::make_cluster_portals`]).
pub(crate) fn fill_outside(
    tree: &mut Tree,
    planes: &PlaneSet,
    portals: &Portals,
    occupants: &[Occupant],
    on_plane: OnPlane,
    warnings: &mut Vec<Warning>,
) -> FillOutcome {
    let leaf_count = portals.leaf_portals.len();
    let mut occupant_of: Vec<Option<usize>> = vec![None; leaf_count];
    for (i, o) in occupants.iter().enumerate() {
        let placement = place(tree, planes, o.origin, on_plane, |c| {
            cluster_contents(&tree.nodes[c as usize])
        });
        let in_solid = match placement {
            Placement::Sealed => true,
            Placement::OnSealingFace => false,
            // Inside detail brushes, which do not seal: it still marks open space.
            Placement::Open(_) => tree
                .leaves_touching(planes, o.origin)
                .iter()
                .all(|&l| engine_contents(tree.nodes[l as usize].contents) == contents::SOLID),
        };
        if in_solid {
            warnings.push(Warning::EntityInSolid {
                entity: o.entity,
                classname: o.classname.clone(),
                origin: o.origin,
                line: o.line,
            });
        }
        if let Placement::Open(cluster) = placement {
            occupant_of[cluster as usize].get_or_insert(i);
        }
    }
    if occupant_of.iter().all(Option::is_none) {
        return FillOutcome::NoOccupants;
    }
    let contents_of = |cluster: u32| cluster_contents_of(tree, portals, cluster);
    let reached = flood_from_void(portals, contents_of);
    let leaking = (0..leaf_count)
        .filter(|&l| reached[l])
        .filter_map(|l| occupant_of[l].map(|o| (o, l as u32)))
        .min();
    if let Some((o, leaf)) = leaking {
        let occupant = occupants[o].clone();
        let path = path_to_outside(portals, &contents_of, leaf, occupant.origin);
        let mut pointfile = vec![occupant.origin];
        pointfile.extend(
            path.iter()
                .map(|&p| portals.portals[p as usize].winding.center()),
        );
        let beyond_brushes = !portals
            .leaf_bounds(portals.outside)
            .contains(occupant.origin);
        let exit = if beyond_brushes {
            Vec::new()
        } else {
            exit_faces(tree, portals, &contents_of, leaf, &path, occupant.origin)
        };
        return FillOutcome::Leaked(Leak {
            occupant,
            pointfile,
            exit,
            beyond_brushes,
        });
    }
    FillOutcome::Sealed {
        filled: fill_reached(tree, &reached),
    }
}

/// Fills what the void reaches in `tree` (a clip hull's, with `portals` its leaf portals)
/// without asking where any entity is: for a clip hull of a sealed world in which no point
/// entity stands in open space (each near enough a wall to be inside the grown brushes). A
/// sealed world's clip hulls are sealed too, so the flood cannot reach the rooms; their open
/// space stays as it is.
pub(crate) fn fill_from_void(tree: &mut Tree, portals: &Portals) {
    let reached = flood_from_void(portals, |c| cluster_contents_of(tree, portals, c));
    fill_reached(tree, &reached);
}

/// The contents the flood sees in `cluster` of `portals` (the outside is open).
fn cluster_contents_of(tree: &Tree, portals: &Portals, cluster: u32) -> i32 {
    if cluster == portals.outside {
        contents::EMPTY
    } else {
        cluster_contents(&tree.nodes[cluster as usize])
    }
}

/// A cluster's structural contents (its own, when it is a leaf).
fn cluster_contents(node: &TreeNode) -> i32 {
    node.cluster.unwrap_or(node.contents)
}

/// Per cluster of `portals`, whether the void reaches it through open portals.
fn flood_from_void(portals: &Portals, contents_of: impl Fn(u32) -> i32) -> Vec<bool> {
    let mut reached = vec![false; portals.leaf_portals.len()];
    reached[portals.outside as usize] = true;
    let mut queue = VecDeque::from([portals.outside]);
    while let Some(leaf) = queue.pop_front() {
        for &p in &portals.leaf_portals[leaf as usize] {
            let next = portals.other(p, leaf);
            if !reached[next as usize] && !is_opaque(contents_of(next)) {
                reached[next as usize] = true;
                queue.push_back(next);
            }
        }
    }
    reached
}

/// Makes every cluster `reached` marks solid, with the leaves below it; returns the leaves.
fn fill_reached(tree: &mut Tree, reached: &[bool]) -> usize {
    let mut filled = 0;
    for (cluster, &r) in reached.iter().enumerate().take(tree.nodes.len()) {
        if r && tree.nodes[cluster].cluster.is_some() {
            tree.nodes[cluster].cluster = Some(contents::SOLID);
            for leaf in tree.leaves_below(cluster as u32) {
                tree.nodes[leaf as usize].contents = contents::SOLID;
                filled += 1;
            }
        }
    }
    filled
}

/// The brush sides of a filled `tree` that face open space: on a portal of `portals` whose
/// other leaf is not opaque, facing out of their leaf into it.
pub(crate) fn visible_sides(tree: &Tree, portals: &Portals) -> VisibleSides {
    let mut visible = VisibleSides::new();
    for p in &portals.portals {
        let (Some(plane), [front, back]) = (p.plane_id, p.nodes) else {
            continue;
        };
        if front == portals.outside || back == portals.outside {
            continue;
        }
        for (owner, viewer, owner_is_front) in [(front, back, true), (back, front, false)] {
            if is_opaque(tree.nodes[viewer as usize].contents) {
                continue;
            }
            // A side looks out of its brush backwards along the plane when the brush lies in
            // front of it.
            for b in &tree.nodes[owner as usize].brushes {
                if b.sides
                    .iter()
                    .any(|s| s.plane == plane && s.flipped == owner_is_front)
                {
                    visible.insert((b.source, plane));
                }
            }
        }
    }
    visible
}

/// How the space inside a sealed map that no point entity reaches is filled (ericw-tools'
/// `-filltype`, with `-filldetail` in [`crate::CompileOptions::fill_detail`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum FillType {
    /// As ericw-tools decides for Quake maps: from the inside, in every hull.
    #[default]
    Auto,
    /// After the void, every place no point entity reaches is filled, in each hull by what
    /// reaches there in that hull.
    Inside,
    /// Only the void outside the map is filled.
    Outside,
}

impl std::str::FromStr for FillType {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(FillType::Auto),
            "inside" => Ok(FillType::Inside),
            "outside" => Ok(FillType::Outside),
            _ => Err(format!("unknown fill type {s:?} (auto, inside, outside)")),
        }
    }
}

/// What `fill_unreached` floods over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reach {
    /// Vis clusters by their structural contents: detail neither blocks the flood nor is filled
    /// apart from its cluster.
    Clusters,
    /// Leaves: solid detail blocks the flood too, so a pocket closed by detail brushes is filled
    /// (`-filldetail`). Fences, which are seen through, do not block.
    Leaves,
}

/// After [`fill_outside`] sealed `tree`, fill every open leaf (or cluster, by `reach`) that no
/// occupant reaches through open ones: `portals` are between those units. An occupant reaches
/// every open unit within [`quake_formats::geom::ON_EPSILON`] of it (a light on a floor holds
/// the room above). Returns how many leaves became solid.
pub(crate) fn fill_unreached(
    tree: &mut Tree,
    planes: &PlaneSet,
    portals: &Portals,
    occupants: &[Occupant],
    reach: Reach,
) -> usize {
    let contents_of = |tree: &Tree, unit: u32| {
        let node = &tree.nodes[unit as usize];
        match reach {
            Reach::Clusters => node.cluster.unwrap_or(node.contents),
            Reach::Leaves => node.contents,
        }
    };
    let open = |c: i32| match reach {
        Reach::Clusters => !is_opaque(c),
        Reach::Leaves => !is_opaque(c) && c != DETAIL_WALL,
    };
    let mut reached = vec![false; portals.leaf_portals.len()];
    reached[portals.outside as usize] = true;
    let mut queue = VecDeque::new();
    for o in occupants {
        let touching = match reach {
            Reach::Clusters => tree.clusters_touching(planes, o.origin),
            Reach::Leaves => tree.leaves_touching(planes, o.origin),
        };
        for unit in touching {
            if !reached[unit as usize] && open(contents_of(tree, unit)) {
                reached[unit as usize] = true;
                queue.push_back(unit);
            }
        }
    }
    while let Some(unit) = queue.pop_front() {
        for &p in &portals.leaf_portals[unit as usize] {
            let next = portals.other(p, unit);
            if !reached[next as usize] && open(contents_of(tree, next)) {
                reached[next as usize] = true;
                queue.push_back(next);
            }
        }
    }
    let mut filled = 0;
    for (unit, &was_reached) in reached.iter().enumerate().take(tree.nodes.len()) {
        let node = &tree.nodes[unit];
        let is_unit = match reach {
            Reach::Clusters => node.cluster.is_some(),
            Reach::Leaves => node.is_leaf(),
        };
        if !is_unit || was_reached || !open(contents_of(tree, unit as u32)) {
            continue;
        }
        for leaf in tree.leaves_below(unit as u32) {
            let leaf = &mut tree.nodes[leaf as usize];
            if leaf.contents != contents::SOLID {
                leaf.contents = contents::SOLID;
                filled += 1;
            }
        }
    }
    // A cluster all of whose leaves are filled is solid structure now.
    for cluster in 0..tree.nodes.len() {
        if tree.nodes[cluster].cluster.is_some()
            && tree
                .leaves_below(cluster as u32)
                .iter()
                .all(|&l| tree.nodes[l as usize].contents == contents::SOLID)
        {
            tree.nodes[cluster].cluster = Some(contents::SOLID);
        }
    }
    filled
}

#[derive(PartialEq)]
struct Visit {
    dist: f64,
    portal: u32,
}

impl Eq for Visit {}

impl Ord for Visit {
    fn cmp(&self, o: &Self) -> Ordering {
        // Min-heap on distance, ties by portal index for a deterministic path.
        o.dist
            .total_cmp(&self.dist)
            .then_with(|| o.portal.cmp(&self.portal))
    }
}

impl PartialOrd for Visit {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// The shortest path through portal centres from `origin` in `start` to the outside box: the
/// portals it passes, the last one on the box.
fn path_to_outside(
    portals: &Portals,
    contents_of: &dyn Fn(u32) -> i32,
    start: u32,
    origin: DVec3,
) -> Vec<u32> {
    let n = portals.portals.len();
    let centre: Vec<DVec3> = portals.portals.iter().map(|p| p.winding.center()).collect();
    let mut dist = vec![f64::INFINITY; n];
    let mut prev = vec![u32::MAX; n];
    let mut heap = BinaryHeap::new();
    for &p in &portals.leaf_portals[start as usize] {
        let d = (centre[p as usize] - origin).length();
        if d < dist[p as usize] && !is_opaque(contents_of(portals.other(p, start))) {
            dist[p as usize] = d;
            heap.push(Visit { dist: d, portal: p });
        }
    }
    while let Some(Visit { dist: d, portal }) = heap.pop() {
        if d > dist[portal as usize] {
            continue;
        }
        let nodes = portals.portals[portal as usize].nodes;
        if nodes.contains(&portals.outside) {
            let mut path = Vec::new();
            let mut p = portal;
            while p != u32::MAX {
                path.push(p);
                p = prev[p as usize];
            }
            path.reverse();
            return path;
        }
        for leaf in nodes {
            if is_opaque(contents_of(leaf)) {
                continue;
            }
            for &q in &portals.leaf_portals[leaf as usize] {
                let nd = d + (centre[q as usize] - centre[portal as usize]).length();
                if nd < dist[q as usize] && !is_opaque(contents_of(portals.other(q, leaf))) {
                    dist[q as usize] = nd;
                    prev[q as usize] = portal;
                    heap.push(Visit {
                        dist: nd,
                        portal: q,
                    });
                }
            }
        }
    }
    Vec::new()
}

/// The sealing faces a leak's path passes last. The path runs from the entity's cluster `start`
/// through the portals of `path` to the outside box; the last cluster on it that borders sealing
/// brushes lies just outside the hole (the box is a margin away from every brush), and the faces
/// it touches nearest to where the path entered it frame the hole.
fn exit_faces(
    tree: &Tree,
    portals: &Portals,
    contents_of: &dyn Fn(u32) -> i32,
    start: u32,
    path: &[u32],
    origin: DVec3,
) -> Vec<ExitFace> {
    // Each cluster on the path, with the point the path enters it by.
    let mut visited = vec![(start, origin)];
    let mut cluster = start;
    for &p in path {
        cluster = portals.other(p, cluster);
        visited.push((cluster, portals.portals[p as usize].winding.center()));
    }
    for &(cluster, entry) in visited.iter().rev() {
        if cluster == portals.outside {
            continue;
        }
        let mut faces: Vec<ExitFace> = portals.leaf_portals[cluster as usize]
            .iter()
            .filter(|&&p| is_opaque(contents_of(portals.other(p, cluster))))
            .filter_map(|&p| sealing_face(tree, portals, p, portals.other(p, cluster)))
            .collect();
        if faces.is_empty() {
            continue;
        }
        faces.sort_by(|a, b| {
            let (da, db) = ((a.point - entry).length(), (b.point - entry).length());
            da.total_cmp(&db).then(a.brush.cmp(&b.brush))
        });
        let mut named: Vec<ExitFace> = Vec::new();
        for f in faces {
            if named.len() < EXIT_FACES && !named.iter().any(|n| n.brush == f.brush) {
                named.push(f);
            }
        }
        return named;
    }
    Vec::new()
}

/// The face of a brush in the sealing cluster `solid` that portal `p` lies on: among the brush
/// fragments filling the cluster's leaves, the textured side on the portal's plane nearest to it.
fn sealing_face(tree: &Tree, portals: &Portals, p: u32, solid: u32) -> Option<ExitFace> {
    let portal = &portals.portals[p as usize];
    let plane = portal.plane_id?;
    let point = portal.winding.center();
    tree.leaves_below(solid)
        .into_iter()
        .flat_map(|leaf| &tree.nodes[leaf as usize].brushes)
        .flat_map(|b| b.sides.iter().map(move |s| (b, s)))
        .filter(|(_, s)| s.plane == plane && s.texinfo.is_some())
        .map(|(b, s)| (b, s, (s.winding.center() - point).length()))
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(b, s, _)| ExitFace {
            brush: b.source,
            texinfo: s.texinfo,
            point,
        })
}
