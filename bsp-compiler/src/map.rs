//! `.map` parsing: the standard Quake format and Valve 220, into entities with brushes.
//!
//! Syntax errors name the file, line and column plus the entity and brush being read. Brush
//! geometry is not checked here (see `crate::brush`).

use crate::texinfo::Projection;
use glam::DVec3;
use quake_formats::entities::Entity;
use quake_formats::geom::Plane;
use std::path::{Path, PathBuf};

/// A syntax error in a `.map` file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}:{column}: {message} (entity {entity}{})", file.display(), brush.map(|b| format!(", brush {b}")).unwrap_or_default())]
pub struct MapError {
    /// The file being parsed.
    pub file: PathBuf,
    /// The line of the error (from 1).
    pub line: usize,
    /// The column of the error (from 1).
    pub column: usize,
    /// The index of the entity being read.
    pub entity: usize,
    /// The index within the entity of the brush being read, if one is.
    pub brush: Option<usize>,
    /// What is wrong.
    pub message: String,
}

/// One brush face as written: three points, a texture name and its projection.
#[derive(Debug, Clone, PartialEq)]
pub struct MapFace {
    /// Three points on the face's plane, clockwise seen from outside the brush.
    pub points: [DVec3; 3],
    /// The texture's name.
    pub texture: String,
    /// How the texture is projected onto the face.
    pub projection: Projection,
    /// The face's line in the `.map`.
    pub line: usize,
}

impl MapFace {
    /// The face's plane (outward facing) in coordinates relative to `origin`, snapped about
    /// its three points' centre; `None` when the points are collinear.
    pub fn plane(&self, origin: DVec3) -> Option<Plane> {
        let [a, b, c] = self.points.map(|p| p - origin);
        Plane::from_points(a, b, c).map(|p| p.snapped((a + b + c) / 3.0))
    }
}

/// One brush as written: its faces, in order.
#[derive(Debug, Clone, PartialEq)]
pub struct MapBrush {
    /// The brush's faces.
    pub faces: Vec<MapFace>,
    /// The brush's line in the `.map`.
    pub line: usize,
}

/// One entity as written: its keys and its brushes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MapEntity {
    /// The entity's keys and values.
    pub entity: Entity,
    /// The entity's brushes.
    pub brushes: Vec<MapBrush>,
    /// The entity's line in the `.map`.
    pub line: usize,
}

/// A parsed `.map` file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MapFile {
    /// The entities in file order; worldspawn first in a valid map.
    pub entities: Vec<MapEntity>,
}

impl MapFile {
    /// Drop the folder from every face's texture name (`base/metal1` becomes `metal1`), as
    /// ericw-tools' qbsp does for Quake 1 maps: editors that load textures from folders write
    /// the folder into the name, but WADs, the texture lump and the name rules (`*`, `sky`,
    /// `clip`...) know the bare name only.
    pub fn drop_texture_folders(&mut self) {
        let faces = self
            .entities
            .iter_mut()
            .flat_map(|e| &mut e.brushes)
            .flat_map(|b| &mut b.faces);
        for face in faces {
            if let Some(bare) = texture_without_folder(&face.texture) {
                face.texture = bare.to_string();
            }
        }
    }
}

/// The part of `texture` after its last `/` (only `/`: ericw-tools leaves `\` alone), when it
/// has a folder and the part is not empty.
fn texture_without_folder(texture: &str) -> Option<&str> {
    texture
        .rsplit_once('/')
        .map(|(_, bare)| bare)
        .filter(|bare| !bare.is_empty())
}

/// A `.map` file's text. Quake text is Latin-1: bytes that are not UTF-8 become the chars of
/// the same value.
pub fn read_map_text(path: &Path) -> std::io::Result<String> {
    let bytes = std::fs::read(path)?;
    Ok(match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    })
}

/// Parse `text`; `file` is only used in error messages.
pub fn parse_map(file: &Path, text: &str) -> Result<MapFile, MapError> {
    let mut p = Parser {
        lex: Lexer::new(text),
        file,
        entity: 0,
        brush: None,
    };
    let mut entities = Vec::new();
    loop {
        p.lex.skip_blank();
        if p.lex.at_end() {
            break;
        }
        p.entity = entities.len();
        p.brush = None;
        entities.push(p.entity_block()?);
    }
    Ok(MapFile { entities })
}

struct Lexer<'a> {
    text: &'a [u8],
    pos: usize,
    line: usize,
    line_start: usize,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str) -> Self {
        Lexer {
            text: text.as_bytes(),
            pos: 0,
            line: 1,
            line_start: 0,
        }
    }

    fn at_end(&self) -> bool {
        self.pos >= self.text.len()
    }

    fn column(&self) -> usize {
        self.pos - self.line_start + 1
    }

    fn bump(&mut self) -> Option<u8> {
        let c = *self.text.get(self.pos)?;
        self.pos += 1;
        if c == b'\n' {
            self.line += 1;
            self.line_start = self.pos;
        }
        Some(c)
    }

    /// Skip whitespace (CR and LF alike) and `//` comments.
    fn skip_blank(&mut self) {
        while let Some(&c) = self.text.get(self.pos) {
            if c.is_ascii_whitespace() {
                self.bump();
            } else if c == b'/' && self.text.get(self.pos + 1) == Some(&b'/') {
                while let Some(c) = self.bump() {
                    if c == b'\n' {
                        break;
                    }
                }
            } else {
                break;
            }
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_blank();
        self.text.get(self.pos).copied()
    }

    /// A run of non-blank bytes; `stop_at_brackets` also ends it at `( ) [ ] { }`.
    fn word(&mut self, stop_at_brackets: bool) -> &'a str {
        self.skip_blank();
        let start = self.pos;
        while let Some(&c) = self.text.get(self.pos) {
            if c.is_ascii_whitespace()
                || (stop_at_brackets && matches!(c, b'(' | b')' | b'[' | b']' | b'{' | b'}' | b'"'))
            {
                break;
            }
            self.pos += 1;
        }
        // Bytes come from a &str and we only stop at ASCII, so this is valid UTF-8.
        std::str::from_utf8(&self.text[start..self.pos]).unwrap_or("")
    }
}

/// A finite number as `f64`'s parser reads `word`. Most of a map's numbers are whole (`-128`):
/// up to 15 digits, below 2^53, they are read digit by digit into the same value (`-0` too).
fn map_number(word: &str) -> Option<f64> {
    let (negative, digits) = match word.strip_prefix('-') {
        Some(digits) => (true, digits),
        None => (false, word),
    };
    if (1..=15).contains(&digits.len()) && digits.bytes().all(|b| b.is_ascii_digit()) {
        let whole = digits
            .bytes()
            .fold(0u64, |n, b| n * 10 + u64::from(b - b'0')) as f64;
        return Some(if negative { -whole } else { whole });
    }
    word.parse::<f64>().ok().filter(|v| v.is_finite())
}

struct Parser<'a> {
    lex: Lexer<'a>,
    file: &'a Path,
    entity: usize,
    brush: Option<usize>,
}

impl Parser<'_> {
    fn error(&self, message: impl Into<String>) -> MapError {
        MapError {
            file: self.file.to_path_buf(),
            line: self.lex.line,
            column: self.lex.column(),
            entity: self.entity,
            brush: self.brush,
            message: message.into(),
        }
    }

    fn expect(&mut self, c: u8) -> Result<(), MapError> {
        match self.lex.peek() {
            Some(found) if found == c => {
                self.lex.bump();
                Ok(())
            }
            Some(found) => Err(self.error(format!(
                "expected '{}', found '{}'",
                c as char, found as char
            ))),
            None => Err(self.error(format!(
                "expected '{}', found the end of the file",
                c as char
            ))),
        }
    }

    fn number(&mut self) -> Result<f64, MapError> {
        self.lex.skip_blank();
        let (line, column) = (self.lex.line, self.lex.column());
        let word = self.lex.word(true);
        match map_number(word) {
            Some(v) => Ok(v),
            None => {
                let mut e = self.error(if word.is_empty() {
                    "expected a number".to_string()
                } else {
                    format!("expected a number, found {word:?}")
                });
                e.line = line;
                e.column = column;
                Err(e)
            }
        }
    }

    fn quoted(&mut self) -> Result<String, MapError> {
        self.expect(b'"')?;
        let start = self.lex.pos;
        loop {
            match self.lex.bump() {
                Some(b'"') => break,
                Some(_) => {}
                None => return Err(self.error("unterminated string")),
            }
        }
        Ok(String::from_utf8_lossy(&self.lex.text[start..self.lex.pos - 1]).into_owned())
    }

    fn entity_block(&mut self) -> Result<MapEntity, MapError> {
        let line = self.lex.line;
        self.expect(b'{')?;
        let mut entity = MapEntity {
            line,
            ..MapEntity::default()
        };
        loop {
            match self.lex.peek() {
                Some(b'"') => {
                    let key = self.quoted()?;
                    let value = self.quoted()?;
                    entity.entity.pairs.push((key, value));
                }
                Some(b'{') => {
                    self.brush = Some(entity.brushes.len());
                    entity.brushes.push(self.brush_block()?);
                    self.brush = None;
                }
                Some(b'}') => {
                    self.lex.bump();
                    return Ok(entity);
                }
                Some(_) => {
                    let word = self.lex.word(true).to_string();
                    return Err(self.error(format!(
                        "expected a \"key\", a brush or '}}', found {word:?}"
                    )));
                }
                None => return Err(self.error("the file ends inside an entity")),
            }
        }
    }

    fn brush_block(&mut self) -> Result<MapBrush, MapError> {
        let line = self.lex.line;
        self.expect(b'{')?;
        let mut faces = Vec::new();
        loop {
            match self.lex.peek() {
                Some(b'(') => faces.push(self.face()?),
                Some(b'}') => {
                    self.lex.bump();
                    return Ok(MapBrush { faces, line });
                }
                Some(_) => {
                    let word = self.lex.word(true).to_string();
                    return Err(self.error(format!(
                        "expected a brush face '(' or '}}', found {word:?} (only Quake and Valve 220 brushes are supported)"
                    )));
                }
                None => return Err(self.error("the file ends inside a brush")),
            }
        }
    }

    fn point(&mut self) -> Result<DVec3, MapError> {
        self.expect(b'(')?;
        let p = DVec3::new(self.number()?, self.number()?, self.number()?);
        self.expect(b')')?;
        Ok(p)
    }

    fn axis(&mut self) -> Result<[f64; 4], MapError> {
        self.expect(b'[')?;
        let v = [
            self.number()?,
            self.number()?,
            self.number()?,
            self.number()?,
        ];
        self.expect(b']')?;
        Ok(v)
    }

    fn face(&mut self) -> Result<MapFace, MapError> {
        let line = self.lex.line;
        let points = [self.point()?, self.point()?, self.point()?];
        let texture = match self.lex.peek() {
            Some(b'"') => self.quoted()?,
            _ => self.lex.word(false).to_string(),
        };
        if texture.is_empty() {
            return Err(self.error("expected a texture name"));
        }
        let projection = if self.lex.peek() == Some(b'[') {
            let u = self.axis()?;
            let v = self.axis()?;
            let _rotation = self.number()?;
            let scale = [self.number()?, self.number()?];
            Projection::Valve { u, v, scale }
        } else {
            let shift = [self.number()?, self.number()?];
            let rotation = self.number()?;
            let scale = [self.number()?, self.number()?];
            Projection::Standard {
                shift,
                rotation,
                scale,
            }
        };
        // Quake 2/3-style surface flags and values may follow on the same line: ignore them.
        while self
            .lex
            .peek()
            .is_some_and(|c| c == b'-' || c == b'+' || c == b'.' || c.is_ascii_digit())
            && self.lex.line == line
        {
            self.number()?;
        }
        Ok(MapFace {
            points,
            texture,
            projection,
            line,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Whole numbers read digit by digit are the values `f64`'s parser gives, bit for bit.
        #[test]
        fn whole_numbers_read_as_f64_reads_them(n in -999_999_999_999_999i64..=999_999_999_999_999, zeros in 0usize..3, minus in any::<bool>()) {
            let digits = format!("{}{}", "0".repeat(zeros), n.unsigned_abs());
            let word = if minus || n < 0 { format!("-{digits}") } else { digits };
            let expected = word.parse::<f64>().ok();
            prop_assert_eq!(map_number(&word).map(f64::to_bits), expected.map(f64::to_bits));
        }
    }

    #[test]
    fn map_numbers_past_the_whole_ones() {
        for word in [
            "-0",
            "0",
            "-",
            "",
            "1.5",
            "-2.25e3",
            "+7",
            "0x10",
            "1234567890123456",
            "inf",
            "nan",
        ] {
            let expected = word.parse::<f64>().ok().filter(|v| v.is_finite());
            assert_eq!(
                map_number(word).map(f64::to_bits),
                expected.map(f64::to_bits),
                "{word}"
            );
        }
    }

    fn parse(text: &str) -> Result<MapFile, MapError> {
        parse_map(Path::new("t.map"), text)
    }

    #[test]
    fn standard_format_with_comments_and_crlf() {
        let text = "// a comment\r\n{\r\n\"classname\" \"worldspawn\"\r\n{\r\n( 0 0 0 ) ( 0 1 0 ) ( 1 0 0 ) +0floor 16 -8 90 0.5 2 // trailing\r\n}\r\n}\r\n";
        let map = parse(text).expect("parse");
        assert_eq!(map.entities.len(), 1);
        let face = &map.entities[0].brushes[0].faces[0];
        assert_eq!(face.texture, "+0floor");
        assert_eq!(face.line, 5);
        assert_eq!(
            face.projection,
            Projection::Standard {
                shift: [16.0, -8.0],
                rotation: 90.0,
                scale: [0.5, 2.0]
            }
        );
    }

    #[test]
    fn valve_format_and_scientific_floats() {
        let text = "{\n\"mapversion\" \"220\"\n{\n( 1e1 0 0 ) ( 0 -1.5E+1 0 ) ( .5 0 1 ) {fence [ 1 0 0 -16 ] [ 0 0 -1 0 ] 0 1 1\n}\n}";
        let map = parse(text).expect("parse");
        let face = &map.entities[0].brushes[0].faces[0];
        assert_eq!(face.points[0].x, 10.0);
        assert_eq!(face.points[1].y, -15.0);
        assert_eq!(face.points[2].x, 0.5);
        assert_eq!(face.texture, "{fence");
        assert!(matches!(face.projection, Projection::Valve { .. }));
    }

    #[test]
    fn texture_folders_are_dropped_up_to_the_last_slash() {
        assert_eq!(texture_without_folder("base/metal1"), Some("metal1"));
        assert_eq!(texture_without_folder("a/b/*water1"), Some("*water1"));
        assert_eq!(texture_without_folder("metal1"), None);
        assert_eq!(texture_without_folder("base\\metal1"), None);
        assert_eq!(texture_without_folder("base/"), None);
    }

    #[test]
    fn ignores_quake2_style_surface_values() {
        let text = "{\n{\n( 0 0 0 ) ( 0 1 0 ) ( 1 0 0 ) a 0 0 0 1 1 0 0 0\n( 0 0 0 ) ( 0 1 0 ) ( 1 0 0 ) b 0 0 0 1 1\n}\n}";
        let map = parse(text).expect("parse");
        assert_eq!(map.entities[0].brushes[0].faces.len(), 2);
    }

    #[test]
    fn errors_name_line_column_entity_and_brush() {
        let text = "{\n\"classname\" \"worldspawn\"\n}\n{\n\"classname\" \"func_door\"\n{\n( 0 0 0 ) ( 0 1 0 ) ( 1 0 x ) a 0 0 0 1 1\n}\n}\n";
        let err = parse(text).expect_err("bad number");
        assert_eq!((err.line, err.column), (7, 27));
        assert_eq!((err.entity, err.brush), (1, Some(0)));
        let msg = err.to_string();
        assert!(msg.starts_with("t.map:7:27:"), "{msg}");
        assert!(msg.contains("entity 1, brush 0"), "{msg}");
    }

    #[test]
    fn unterminated_entity_is_an_error() {
        let err = parse("{\n\"classname\" \"worldspawn\"\n").expect_err("eof");
        assert!(err.message.contains("ends inside an entity"));
        let err = parse("{ \"a\" \"b\" }\n}").expect_err("stray brace");
        assert_eq!(err.entity, 1);
    }

    #[test]
    fn nan_is_not_a_number() {
        let err =
            parse("{\n{\n( nan 0 0 ) ( 0 1 0 ) ( 1 0 0 ) a 0 0 0 1 1\n}\n}").expect_err("nan");
        assert!(err.message.contains("expected a number"));
    }
}
