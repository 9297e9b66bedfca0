use std::path::PathBuf;

/// Everything that can go wrong reading or writing a Quake file. Messages name the lump, record
/// or line so a user can find the problem.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// A read ran past the end of its data.
    #[error(
        "{what}: needs {need} bytes at offset {offset}, but only {len} are there (truncated file?)"
    )]
    Truncated {
        /// The structure being read (`"BSP header"`, a lump name).
        what: String,
        /// Byte offset of the read in the data read from (the lump, or the whole file).
        offset: usize,
        /// Bytes the read needed.
        need: usize,
        /// Length of the data read from, in bytes.
        len: usize,
    },
    /// The first four bytes are neither BSP29's version 29, `BSP2` nor `2PSB`; holds them as a
    /// little-endian number.
    #[error("not a BSP file: version {0:#010x} is neither 29, \"BSP2\" nor \"2PSB\"")]
    UnknownBspVersion(u32),
    /// A header entry places its lump (partly) outside the file.
    #[error(
        "{lump} lump: offset {offset} and length {length} run outside the {file_len}-byte file"
    )]
    LumpOutOfFile {
        /// The lump's name (`"faces"`).
        lump: &'static str,
        /// Byte offset the header gives.
        offset: i64,
        /// Length in bytes the header gives.
        length: i64,
        /// Size of the whole file in bytes.
        file_len: usize,
    },
    /// A lump of fixed-size records holds a partial record.
    #[error("{lump} lump: length {length} is not a multiple of its {record}-byte record")]
    LumpSize {
        /// The lump's name.
        lump: &'static str,
        /// The lump's length in bytes.
        length: usize,
        /// Size of one record in this BSP version, in bytes.
        record: usize,
    },
    /// A lump's contents are damaged, or a value does not fit the version being written.
    #[error("{lump} lump: {detail}")]
    BadLump {
        /// The lump's name, or the structure read (`"BSPX"`, `".lit"`).
        lump: &'static str,
        /// What is wrong, with the values involved.
        detail: String,
    },
    /// The data has more of something than BSP29 can hold; BSP2 can.
    #[error(
        "BSP29 limit exceeded: {what} is {count}, the format allows at most {max}; write BSP2 instead (--bsp2)"
    )]
    Bsp29Limit {
        /// What is over the limit (`"the node count"`).
        what: &'static str,
        /// How many or how large it is.
        count: usize,
        /// The most BSP29 allows.
        max: usize,
    },
    /// A node or leaf bound, rounded outward to whole units, does not fit the 16-bit integer
    /// BSP29 and 2PSB store bounds in; BSP2 stores floats.
    #[error(
        "{version} limit exceeded: {record} {index}'s bound {value} does not fit a 16-bit integer (-32768 to 32767 map units); write BSP2 instead (--bsp2)"
    )]
    ShortBound {
        /// The version being written (BSP29 or 2PSB).
        version: crate::bsp_version::BspVersion,
        /// `"node"` or `"leaf"`.
        record: &'static str,
        /// The record's index in its lump.
        index: usize,
        /// The bound as the model holds it, before rounding.
        value: f32,
    },
    /// The file does not start with `WAD2`; holds the four bytes it starts with.
    #[error("not a WAD2 file: magic {0:?}")]
    NotWad2([u8; 4]),
    /// A WAD directory entry or the lump it points at is damaged.
    #[error("WAD lump {index} ({name}): {detail}")]
    BadWadLump {
        /// The entry's position in the directory.
        index: usize,
        /// The entry's name.
        name: String,
        /// What is wrong, with the values involved.
        detail: String,
    },
    /// A palette is not 256 RGB triples; holds the size found in bytes.
    #[error("palette: expected 768 bytes, found {0}")]
    PaletteSize(usize),
    /// [`check_usable`](crate::check_usable) found problems that tools refuse.
    #[error(
        "refused: {count} problem(s) would make tools read out of bounds or never finish \
         ({shown}); `slipgate info` lists them all"
    )]
    Refused {
        /// How many refused problems the file has.
        count: usize,
        /// The first few of them, as the validator words them.
        shown: String,
    },
    /// A text format (the entity lump, a portal file) does not parse.
    #[error("line {line}: {detail}")]
    Syntax {
        /// 1-based line number.
        line: usize,
        /// What was expected and what was found.
        detail: String,
    },
    /// Reading or writing a file failed.
    ///
    /// The OS error is the `source`, so `{:#}` chains print it once.
    #[error("{}", path.display())]
    Io {
        /// The file read or written.
        path: PathBuf,
        /// What the OS reported.
        #[source]
        source: std::io::Error,
    },
}

/// A result whose error defaults to [`FormatError`].
pub type Result<T, E = FormatError> = std::result::Result<T, E>;
