use std::path::PathBuf;

/// Everything that can go wrong reading or writing a Quake file. Messages name the lump, record
/// or line so a user can find the problem.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    #[error(
        "{what}: needs {need} bytes at offset {offset}, but only {len} are there (truncated file?)"
    )]
    Truncated {
        what: String,
        offset: usize,
        need: usize,
        len: usize,
    },
    #[error("not a BSP file: version {0:#010x} is neither 29 nor \"BSP2\"")]
    UnknownBspVersion(u32),
    #[error(
        "{lump} lump: offset {offset} and length {length} run outside the {file_len}-byte file"
    )]
    LumpOutOfFile {
        lump: &'static str,
        offset: i64,
        length: i64,
        file_len: usize,
    },
    #[error("{lump} lump: length {length} is not a multiple of its {record}-byte record")]
    LumpSize {
        lump: &'static str,
        length: usize,
        record: usize,
    },
    #[error("{lump} lump: {detail}")]
    BadLump { lump: &'static str, detail: String },
    #[error(
        "BSP29 limit exceeded: {what} is {count}, the format allows at most {max}; write BSP2 instead (--bsp2)"
    )]
    Bsp29Limit {
        what: &'static str,
        count: usize,
        max: usize,
    },
    #[error("not a WAD2 file: magic {0:?}")]
    NotWad2([u8; 4]),
    #[error("WAD lump {index} ({name}): {detail}")]
    BadWadLump {
        index: usize,
        name: String,
        detail: String,
    },
    #[error("palette: expected 768 bytes, found {0}")]
    PaletteSize(usize),
    #[error(
        "refused: {count} problem(s) would make tools read out of bounds or never finish \
         ({shown}); `slipgate info` lists them all"
    )]
    Refused { count: usize, shown: String },
    #[error("line {line}: {detail}")]
    Syntax { line: usize, detail: String },
    /// The OS error is the `source`, so `{:#}` chains print it once.
    #[error("{}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

pub type Result<T, E = FormatError> = std::result::Result<T, E>;
