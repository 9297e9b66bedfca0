//! A minimal `progs.dat` (QuakeC bytecode, format version 6) so a real engine's server will spawn
//! a map: the free game data has no progs, and Quake refuses to start a server without one.
//!
//! Functions are empty (one `DONE` statement) except two that give the player a model (see
//! [`minimal_progs`]). What the engine needs from the file:
//! - the header's version (6) and CRC (5927): the CRC is not computed over the file; it names the
//!   `progdefs.h` layout of the system globals and entity fields, and engines compare the number;
//! - the system globals and entity fields at exactly the offsets of that layout, because the engine
//!   reads and writes them through C structs (`globalvars_t`, `entvars_t`), not by name;
//! - field *definitions* with those names, because the map's entity text is parsed into fields by
//!   name (`classname`, `origin`, `model`, ...);
//! - the ten functions the engine calls through `globalvars_t`, with non-zero function numbers
//!   (number 0 is the null function and calling it is a `Host_Error`);
//! - a `worldspawn` function (entities are spawned by calling the function named like their
//!   class) that precaches the player model, which every server needs (see [`PLAYER_MODEL`]).

/// QuakeC value types (`etype_t`).
#[derive(Clone, Copy)]
#[repr(u16)]
enum Type {
    String = 1,
    Float = 2,
    Vector = 3,
    Entity = 4,
    Function = 6,
}

impl Type {
    /// How many 4-byte slots a value of this type takes.
    fn slots(self) -> u16 {
        match self {
            Type::Vector => 3,
            _ => 1,
        }
    }
}

use Type::{Entity as E, Float as F, Function as Fn_, String as S, Vector as V};

/// `globalvars_t` after the 28 reserved slots (null, return value, eight 3-slot parameters).
const GLOBALS: &[(&str, Type)] = &[
    ("self", E),
    ("other", E),
    ("world", E),
    ("time", F),
    ("frametime", F),
    ("force_retouch", F),
    ("mapname", S),
    ("deathmatch", F),
    ("coop", F),
    ("teamplay", F),
    ("serverflags", F),
    ("total_secrets", F),
    ("total_monsters", F),
    ("found_secrets", F),
    ("killed_monsters", F),
    ("parm1", F),
    ("parm2", F),
    ("parm3", F),
    ("parm4", F),
    ("parm5", F),
    ("parm6", F),
    ("parm7", F),
    ("parm8", F),
    ("parm9", F),
    ("parm10", F),
    ("parm11", F),
    ("parm12", F),
    ("parm13", F),
    ("parm14", F),
    ("parm15", F),
    ("parm16", F),
    ("v_forward", V),
    ("v_up", V),
    ("v_right", V),
    ("trace_allsolid", F),
    ("trace_startsolid", F),
    ("trace_fraction", F),
    ("trace_endpos", V),
    ("trace_plane_normal", V),
    ("trace_plane_dist", F),
    ("trace_ent", E),
    ("trace_inopen", F),
    ("trace_inwater", F),
    ("msg_entity", E),
    // The functions the engine calls; their slots hold function numbers.
    ("main", Fn_),
    ("StartFrame", Fn_),
    ("PlayerPreThink", Fn_),
    ("PlayerPostThink", Fn_),
    ("ClientKill", Fn_),
    ("ClientConnect", Fn_),
    ("PutClientInServer", Fn_),
    ("ClientDisconnect", Fn_),
    ("SetNewParms", Fn_),
    ("SetChangeParms", Fn_),
];

/// Slots before `self`: OFS_NULL, OFS_RETURN (3) and OFS_PARM0..7 (3 each).
const RESERVED_GLOBALS: u16 = 28;

/// `entvars_t`, in order, from offset 0.
const FIELDS: &[(&str, Type)] = &[
    ("modelindex", F),
    ("absmin", V),
    ("absmax", V),
    ("ltime", F),
    ("movetype", F),
    ("solid", F),
    ("origin", V),
    ("oldorigin", V),
    ("velocity", V),
    ("angles", V),
    ("avelocity", V),
    ("punchangle", V),
    ("classname", S),
    ("model", S),
    ("frame", F),
    ("skin", F),
    ("effects", F),
    ("mins", V),
    ("maxs", V),
    ("size", V),
    ("touch", Fn_),
    ("use", Fn_),
    ("think", Fn_),
    ("blocked", Fn_),
    ("nextthink", F),
    ("groundentity", E),
    ("health", F),
    ("frags", F),
    ("weapon", F),
    ("weaponmodel", S),
    ("weaponframe", F),
    ("currentammo", F),
    ("ammo_shells", F),
    ("ammo_nails", F),
    ("ammo_rockets", F),
    ("ammo_cells", F),
    ("items", F),
    ("takedamage", F),
    ("chain", E),
    ("deadflag", F),
    ("view_ofs", V),
    ("button0", F),
    ("button1", F),
    ("button2", F),
    ("impulse", F),
    ("fixangle", F),
    ("v_angle", V),
    ("idealpitch", F),
    ("netname", S),
    ("enemy", E),
    ("flags", F),
    ("colormap", F),
    ("team", F),
    ("max_health", F),
    ("teleport_time", F),
    ("armortype", F),
    ("armorvalue", F),
    ("waterlevel", F),
    ("watertype", F),
    ("ideal_yaw", F),
    ("yaw_speed", F),
    ("aiment", E),
    ("goalentity", E),
    ("spawnflags", F),
    ("target", S),
    ("targetname", S),
    ("dmg_take", F),
    ("dmg_save", F),
    ("dmg_inflictor", E),
    ("owner", E),
    ("movedir", V),
    ("message", S),
    ("sounds", F),
    ("noise", S),
    ("noise1", S),
    ("noise2", S),
    ("noise3", S),
];

const PROG_VERSION: i32 = 6;
/// The CRC of id's `progdefs.h`, i.e. of the two tables above.
const PROGHEADER_CRC: i32 = 5927;
/// Header: version, crc, six (offset, count) pairs, entityfields.
const HEADER_BYTES: usize = 15 * 4;

/// Opcodes used (`pr_comp.h` numbering).
const OP_DONE: u16 = 0;
const OP_STORE_S: u16 = 33;
const OP_STORE_ENT: u16 = 34;
const OP_CALL1: u16 = 52;
const OP_CALL2: u16 = 53;
/// Parameter slots (`OFS_PARM0`, `OFS_PARM1`).
const OFS_PARM0: u16 = 4;
const OFS_PARM1: u16 = 7;
/// The engine's builtins used, by number: functions 1 and 2 of the file, with a negative first
/// statement naming the builtin.
const BUILTINS: [(&str, i32); 2] = [("precache_model", 20), ("setmodel", 3)];
/// Every server precaches this model: it is the baseline model of the client slots, and
/// spawning fails ("SV_ModelIndex: model progs/player.mdl not precached") without it.
pub const PLAYER_MODEL: &str = "progs/player.mdl";

/// The bytes of a `progs.dat` whose `worldspawn` precaches [`PLAYER_MODEL`] (the file must
/// exist: see [`placeholder_model`]), whose `PutClientInServer` gives the player that model (a
/// client moves its view only with an entity that has a model) and whose other spawn functions,
/// one per name in `classes`, are empty. Classes without a function would be freed too, but only
/// after the engine prints each of them field by field, burying its messages.
pub fn minimal_progs(classes: &[&str]) -> Vec<u8> {
    let mut strings = Strings::default();
    let file = strings.add("slipgate-test.qc");

    let called: Vec<&str> = GLOBALS
        .iter()
        .filter(|(_, t)| matches!(t, Fn_))
        .map(|(name, _)| *name)
        .collect();
    // Function 0 is the null function, then the builtins, then `called` in order.
    let first_called = 1 + BUILTINS.len();

    // System globals, then constants of our own: the model name and the builtins' numbers.
    let mut globals = vec![0u32; usize::from(RESERVED_GLOBALS)];
    let mut global_defs = vec![[0u16, 0, 0, 0]]; // def 0: the null global
    for (name, ty) in GLOBALS {
        let ofs = globals.len() as u16;
        global_defs.push(def(*ty as u16, ofs, strings.add(name)));
        let value = match called.iter().position(|n| n == name) {
            Some(i) => (first_called + i) as u32, // function number
            None => 0,
        };
        globals.extend(std::iter::repeat_n(value, usize::from(ty.slots())));
    }
    let self_global = RESERVED_GLOBALS; // `self` is the first system global
    let model_name = globals.len() as u16;
    globals.push(strings.add(PLAYER_MODEL) as u32);
    let (precache_model, setmodel) = (model_name + 1, model_name + 2);
    globals.extend([1, 2]);

    // Statement 0 is never run; the others are the bodies, each ended by DONE.
    const EMPTY: i32 = 1;
    const WORLDSPAWN: i32 = 2; // precache_model(PLAYER_MODEL);
    const PUT_CLIENT_IN_SERVER: i32 = 5; // setmodel(self, PLAYER_MODEL);
    let statements = [
        [OP_DONE, 0, 0, 0],
        [OP_DONE, 0, 0, 0],
        [OP_STORE_S, model_name, OFS_PARM0, 0],
        [OP_CALL1, precache_model, 0, 0],
        [OP_DONE, 0, 0, 0],
        [OP_STORE_ENT, self_global, OFS_PARM0, 0],
        [OP_STORE_S, model_name, OFS_PARM1, 0],
        [OP_CALL2, setmodel, 0, 0],
        [OP_DONE, 0, 0, 0],
    ];

    // first_statement, parm_start, locals, profile, s_name, s_file, numparms, parm_size[8]
    let mut functions = vec![[0i32; 9]];
    for (name, number) in BUILTINS {
        functions.push([-number, 0, 0, 0, strings.add(name), file, 0, 0, 0]);
    }
    let mut classes: Vec<&str> = classes.to_vec();
    classes.sort_unstable();
    classes.dedup();
    classes.retain(|c| *c != "worldspawn" && !called.contains(c));
    let bodies = called.iter().map(|&name| match name {
        "PutClientInServer" => (name, PUT_CLIENT_IN_SERVER),
        _ => (name, EMPTY),
    });
    let spawns = classes.into_iter().map(|class| (class, EMPTY));
    for (name, first) in bodies.chain([("worldspawn", WORLDSPAWN)]).chain(spawns) {
        functions.push([first, 0, 0, 0, strings.add(name), file, 0, 0, 0]);
    }

    let mut field_defs = vec![[0u16, 0, 0, 0]]; // def 0: the null field
    let mut entity_fields = 0u16;
    for (name, ty) in FIELDS {
        field_defs.push(def(*ty as u16, entity_fields, strings.add(name)));
        entity_fields += ty.slots();
    }

    // Lay out the sections after the header.
    let mut out = vec![0u8; HEADER_BYTES];
    let mut sections = Vec::new();
    let mut section = |out: &mut Vec<u8>, bytes: Vec<u8>, count: usize| {
        sections.push((out.len() as i32, count as i32));
        out.extend(bytes);
    };
    section(
        &mut out,
        flat(&statements, u16::to_le_bytes),
        statements.len(),
    );
    section(
        &mut out,
        flat(&global_defs, u16::to_le_bytes),
        global_defs.len(),
    );
    section(
        &mut out,
        flat(&field_defs, u16::to_le_bytes),
        field_defs.len(),
    );
    let fns: Vec<Vec<u8>> = functions.iter().map(function_bytes).collect();
    section(&mut out, fns.concat(), functions.len());
    let string_len = strings.0.len();
    section(&mut out, strings.0, string_len);
    let global_bytes = globals.iter().flat_map(|g| g.to_le_bytes()).collect();
    section(&mut out, global_bytes, globals.len());

    let mut header = vec![PROG_VERSION, PROGHEADER_CRC];
    header.extend(sections.iter().flat_map(|&(ofs, n)| [ofs, n]));
    header.push(i32::from(entity_fields));
    for (i, v) in header.iter().enumerate() {
        out[i * 4..i * 4 + 4].copy_from_slice(&v.to_le_bytes());
    }
    out
}

/// A tiny valid alias model (`.mdl`, version 6) for [`PLAYER_MODEL`]: one 8x8 skin and one
/// frame of one triangle. The loader dispatches on the magic, so it must really be a model.
pub fn placeholder_model() -> Vec<u8> {
    const SKIN: i32 = 8;
    let mut out = b"IDPO".to_vec();
    let ints = |out: &mut Vec<u8>, v: &[i32]| out.extend(v.iter().flat_map(|x| x.to_le_bytes()));
    let floats = |out: &mut Vec<u8>, v: &[f32]| out.extend(v.iter().flat_map(|x| x.to_le_bytes()));
    ints(&mut out, &[6]); // version
    floats(
        &mut out,
        &[1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
    ); // scale, origin, radius, eye
    // skins, skin width and height, vertices, triangles, frames, synctype, flags
    ints(&mut out, &[1, SKIN, SKIN, 3, 1, 1, 0, 0]);
    floats(&mut out, &[1.0]); // size
    ints(&mut out, &[0]); // a single skin...
    out.extend([0u8; (SKIN * SKIN) as usize]); // ...of palette index 0
    ints(&mut out, &[0, 0, 0, 0, SKIN, 0, 0, 0, SKIN]); // (onseam, s, t) per vertex
    ints(&mut out, &[1, 0, 1, 2]); // one front-facing triangle
    ints(&mut out, &[0]); // a single frame: bounds, 16-byte name, (x, y, z, normal) per vertex
    out.extend([0, 0, 0, 0, 1, 1, 0, 0]);
    out.extend(b"base\0\0\0\0\0\0\0\0\0\0\0\0");
    out.extend([0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0]);
    out
}

/// A `ddef_t`: type, offset, then the 32-bit name offset as two 16-bit halves (little-endian).
fn def(ty: u16, ofs: u16, name: i32) -> [u16; 4] {
    let name = name as u32;
    [ty, ofs, name as u16, (name >> 16) as u16]
}

/// A `dfunction_t`: seven 32-bit values, then eight parameter sizes of one byte (all zero here).
fn function_bytes(f: &[i32; 9]) -> Vec<u8> {
    f.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn flat<T: Copy, const N: usize, const B: usize>(
    records: &[[T; N]],
    bytes: fn(T) -> [u8; B],
) -> Vec<u8> {
    records.iter().flatten().flat_map(|&v| bytes(v)).collect()
}

/// The string table: offset 0 is the empty string, as engines expect for "no string".
struct Strings(Vec<u8>);

impl Default for Strings {
    fn default() -> Self {
        Strings(vec![0])
    }
}

impl Strings {
    fn add(&mut self, s: &str) -> i32 {
        let ofs = self.0.len() as i32;
        self.0.extend(s.as_bytes());
        self.0.push(0);
        ofs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sum(table: &[(&str, Type)]) -> u16 {
        table.iter().map(|(_, t)| t.slots()).sum()
    }

    #[test]
    fn layout_matches_progdefs() {
        // id's progdefs.h: globalvars_t has 92 slots, entvars_t 105.
        assert_eq!(RESERVED_GLOBALS + sum(GLOBALS), 92);
        assert_eq!(sum(FIELDS), 105);
        let bytes = minimal_progs(&["light", "worldspawn"]);
        let word = |i: usize| i32::from_le_bytes(bytes[i * 4..i * 4 + 4].try_into().unwrap());
        assert_eq!((word(0), word(1), word(14)), (6, 5927, 105));
        // The globals section is the last one and ends the file.
        assert_eq!(word(12) as usize + word(13) as usize * 4, bytes.len());
    }
}
