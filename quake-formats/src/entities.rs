//! The entity lump: `{ "key" "value" ... }` blocks, kept as ordered key/value pairs.

use crate::error::{FormatError, Result};
use crate::geom::POINT_EPSILON;

/// ericw-tools' colour rule for `r g b` keys (`_color`, `_minlight_color`...): components all
/// within 0..1 are fractions, otherwise they are 0..255. Returned as fractions.
pub fn normalize_color(c: glam::DVec3) -> glam::DVec3 {
    if c.x <= 1.0 && c.y <= 1.0 && c.z <= 1.0 {
        c
    } else {
        c / 255.0
    }
}

/// One entity: its key/value pairs in file order (keys may repeat; the first one wins on lookup,
/// as in Quake's `ValueForKey`).
///
/// Two entities are equal when their pairs are: where one was read from is not part of it.
#[derive(Debug, Clone, Default)]
pub struct Entity {
    /// Keys and values as written, in file order.
    pub pairs: Vec<(String, String)>,
    /// The line of the text it was read from where its `{` stands (1 is the first line), for
    /// messages; 0 for an entity made in code.
    pub line: usize,
}

impl PartialEq for Entity {
    fn eq(&self, other: &Entity) -> bool {
        self.pairs == other.pairs
    }
}

impl Eq for Entity {}

impl Entity {
    /// The value of the first `key`, if there is one.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.pairs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The `classname` value (`"worldspawn"`, `"info_player_start"`), or `""` when it has none.
    pub fn classname(&self) -> &str {
        self.get("classname").unwrap_or("")
    }

    /// Set `key`, replacing its first occurrence or appending it.
    pub fn set(&mut self, key: &str, value: impl Into<String>) {
        let value = value.into();
        match self.pairs.iter_mut().find(|(k, _)| k == key) {
            Some(pair) => pair.1 = value,
            None => self.pairs.push((key.to_string(), value)),
        }
    }

    /// Remove every pair with `key`.
    pub fn remove(&mut self, key: &str) {
        self.pairs.retain(|(k, _)| k != key);
    }

    /// A key parsed as numbers separated by spaces (`"origin" "0 0 24"`).
    pub fn get_floats<const N: usize>(&self, key: &str) -> Option<[f64; N]> {
        let mut out = [0.0; N];
        let mut parts = self.get(key)?.split_whitespace();
        for slot in &mut out {
            *slot = parts.next()?.parse().ok()?;
        }
        Some(out)
    }

    /// A key parsed as one number (`"light" "300"`); `None` when it is missing or not a number.
    pub fn get_float(&self, key: &str) -> Option<f64> {
        self.get(key)?.trim().parse().ok()
    }

    /// A key read as ericw-tools reads a number (C's `atof`): the number its first word starts
    /// with (`"150x"` is 150), and whether that number was the whole value; `None` when the key
    /// is missing or starts with no number.
    pub fn get_leading_float(&self, key: &str) -> Option<(f64, bool)> {
        let text = self.get(key)?;
        let mut words = text.split_whitespace();
        let first = words.next()?;
        let (value, used) = leading_number(first)?;
        Some((value, used == first.len() && words.next().is_none()))
    }

    /// Where this point entity marks open space for a compiler's outside fill: its `origin`,
    /// unless it stands at the map's origin (where ericw-tools takes it for a brush entity and
    /// skips it) or is marked `_nofill` (or `_lightgrid_hint`) to stand in the void. The caller
    /// leaves out worldspawn and brush entities.
    pub fn fill_origin(&self) -> Option<[f64; 3]> {
        let origin = self.get_floats::<3>("origin")?;
        let marked = |key| self.get_float(key).is_some_and(|v| v != 0.0);
        let at_map_origin = origin.iter().all(|c| c.abs() < POINT_EPSILON);
        (!at_map_origin && !marked("_nofill") && !marked("_lightgrid_hint")).then_some(origin)
    }
}

/// The number `word` starts with (sign, digits, a point, an exponent: C's `strtod` without its
/// hexadecimal and infinite forms), and how many bytes of it that takes.
pub fn leading_number(word: &str) -> Option<(f64, usize)> {
    let bytes = word.as_bytes();
    let digits_from = |mut i: usize| {
        while bytes.get(i).is_some_and(u8::is_ascii_digit) {
            i += 1;
        }
        i
    };
    let mut end = usize::from(matches!(bytes.first(), Some(b'+' | b'-')));
    let int_end = digits_from(end);
    let mut mantissa_digits = int_end - end;
    end = int_end;
    if bytes.get(end) == Some(&b'.') {
        let frac_end = digits_from(end + 1);
        mantissa_digits += frac_end - end - 1;
        end = frac_end;
    }
    if mantissa_digits == 0 {
        return None;
    }
    if matches!(bytes.get(end), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(bytes.get(end + 1), Some(b'+' | b'-')));
        let exp_end = digits_from(end + 1 + sign);
        if exp_end > end + 1 + sign {
            end = exp_end;
        }
    }
    let value: f64 = word[..end].parse().ok()?;
    value.is_finite().then_some((value, end))
}

/// Parse entity text. Quake's format has no escapes: a value runs to the next `"`.
pub fn parse_entities(text: &str) -> Result<Vec<Entity>> {
    let mut entities = Vec::new();
    let mut current: Option<Entity> = None;
    let mut pending_key: Option<String> = None;
    let mut line = 1;
    let mut chars = text.chars().peekable();
    let syntax = |line: usize, detail: &str| FormatError::Syntax {
        line,
        detail: detail.to_string(),
    };
    while let Some(c) = chars.next() {
        match c {
            '\n' => line += 1,
            c if c.is_whitespace() || c == '\0' => {}
            '/' if chars.peek() == Some(&'/') => {
                for c in chars.by_ref() {
                    if c == '\n' {
                        line += 1;
                        break;
                    }
                }
            }
            '{' => {
                if current.is_some() {
                    return Err(syntax(line, "'{' inside an entity"));
                }
                current = Some(Entity {
                    pairs: Vec::new(),
                    line,
                });
            }
            '}' => {
                let entity = current
                    .take()
                    .ok_or_else(|| syntax(line, "'}' without '{'"))?;
                if pending_key.is_some() {
                    return Err(syntax(line, "key without a value"));
                }
                entities.push(entity);
            }
            '"' => {
                let entity = current
                    .as_mut()
                    .ok_or_else(|| syntax(line, "string outside an entity"))?;
                let start_line = line;
                let mut s = String::new();
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\n') => {
                            line += 1;
                            s.push('\n');
                        }
                        Some(c) => s.push(c),
                        None => return Err(syntax(start_line, "unterminated string")),
                    }
                }
                match pending_key.take() {
                    None => pending_key = Some(s),
                    Some(key) => entity.pairs.push((key, s)),
                }
            }
            other => return Err(syntax(line, &format!("unexpected character {other:?}"))),
        }
    }
    if current.is_some() {
        return Err(syntax(line, "missing '}' at end of entities"));
    }
    Ok(entities)
}

/// Entity text as compilers write it: one pair per line.
pub fn write_entities(entities: &[Entity]) -> String {
    let mut out = String::new();
    for e in entities {
        out.push_str("{\n");
        for (k, v) in &e.pairs {
            out.push('"');
            out.push_str(k);
            out.push_str("\" \"");
            out.push_str(v);
            out.push_str("\"\n");
        }
        out.push_str("}\n");
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn numbers_read_as_far_as_they_go() {
        use super::leading_number;
        assert_eq!(leading_number("150"), Some((150.0, 3)));
        assert_eq!(leading_number("150x"), Some((150.0, 3)));
        assert_eq!(leading_number("-1.5e2z"), Some((-150.0, 6)));
        assert_eq!(leading_number("1e"), Some((1.0, 1)));
        assert_eq!(leading_number(".5"), Some((0.5, 2)));
        assert_eq!(leading_number("-"), None);
        assert_eq!(leading_number("x5"), None);
        assert_eq!(leading_number("."), None);
    }

    use super::*;
    use proptest::prelude::*;

    #[test]
    fn parses_pairs_in_order() {
        let text = "{\n\"classname\" \"worldspawn\"\n\"wad\" \"a.wad\"\n}\n{\"classname\" \"light\" \"origin\" \"1 2 3\"}";
        let ents = parse_entities(text).expect("parse");
        assert_eq!(ents.len(), 2);
        assert_eq!(ents[0].classname(), "worldspawn");
        assert_eq!(ents[1].get_floats::<3>("origin"), Some([1.0, 2.0, 3.0]));
        assert_eq!((ents[0].line, ents[1].line), (1, 5));
    }

    #[test]
    fn errors_name_the_line() {
        let err = parse_entities("{\n\"a\" \"b\"\n\"c\"\n}").expect_err("dangling key");
        assert!(err.to_string().contains("line 4"), "{err}");
        let err = parse_entities("{\n\"a\" \"b").expect_err("unterminated");
        assert!(err.to_string().contains("line 2"), "{err}");
    }

    proptest! {
        #[test]
        fn write_then_parse_is_identity(pairs in proptest::collection::vec(("[^\"\\x00]{0,12}", "[^\"\\x00]{0,20}"), 0..8), n in 0usize..4) {
            let ents: Vec<Entity> = (0..n).map(|_| Entity { pairs: pairs.clone(), line: 0 }).collect();
            let text = write_entities(&ents);
            prop_assert_eq!(parse_entities(&text).expect("parse"), ents);
        }
    }
}
