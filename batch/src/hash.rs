//! Content hashes (SHA-256, hex) for cache keys and output checks.

use sha2::{Digest, Sha256};

/// The hex SHA-256 of `bytes`.
pub fn hash_bytes(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// A cache key under construction: named fields, each length-prefixed so that no two different
/// field lists hash alike.
pub struct KeyHasher(Sha256);

impl KeyHasher {
    pub fn new(stage: &str) -> KeyHasher {
        let mut hasher = KeyHasher(Sha256::new());
        hasher.field("stage", stage.as_bytes());
        hasher
    }

    pub fn field(&mut self, name: &str, value: &[u8]) -> &mut KeyHasher {
        for part in [name.as_bytes(), value] {
            self.0.update((part.len() as u64).to_le_bytes());
            self.0.update(part);
        }
        self
    }

    /// A field whose value is written with `fmt::Debug`, streamed rather than built as a string.
    pub fn debug_field(&mut self, name: &str, value: &impl std::fmt::Debug) -> &mut KeyHasher {
        use std::fmt::Write;
        self.field(name, b"(debug)");
        // Writing into a hasher cannot fail.
        let _ = write!(self, "{value:?}");
        self.0.update(b"\0end");
        self
    }

    pub fn finish(self) -> String {
        hex(&self.0.finalize())
    }
}

impl std::fmt::Write for KeyHasher {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_delimited() {
        let key = |a: &str, b: &str| {
            let mut h = KeyHasher::new("s");
            h.field("a", a.as_bytes()).field("b", b.as_bytes());
            h.finish()
        };
        assert_ne!(key("xy", "z"), key("x", "yz"));
        assert_eq!(key("x", "yz"), key("x", "yz"));
        assert_eq!(
            hash_bytes(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
