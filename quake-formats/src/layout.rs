//! Where the parts of a container file (BSP lumps, WAD lumps) sit, so a file read and written back
//! unchanged is byte-identical, padding and unusual lump order included.
//!
//! A reader records the offset of every segment it decoded plus the bytes no segment covers
//! ("filler"). The writer encodes the segments again; when their lengths are unchanged it puts
//! them back where they were, otherwise it lays them out afresh, 4-byte aligned.

/// The recorded placement of a file's segments.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Layout {
    total_len: usize,
    /// Offset and length of each segment, in the order the format's encoder emits them.
    segments: Vec<(usize, usize)>,
    /// Bytes outside the header and every segment, with their offsets.
    filler: Vec<(usize, Vec<u8>)>,
}

impl Layout {
    /// Record a file whose header is `header_len` bytes and whose segments are `segments`.
    pub fn record(file: &[u8], header_len: usize, segments: Vec<(usize, usize)>) -> Layout {
        let mut covered: Vec<(usize, usize)> = segments
            .iter()
            .filter(|s| s.1 > 0)
            .map(|&(o, l)| (o, (o + l).min(file.len())))
            .collect();
        covered.push((0, header_len.min(file.len())));
        covered.sort_unstable();
        let mut filler = Vec::new();
        let mut pos = 0;
        for (start, end) in covered {
            if start > pos {
                filler.push((pos, file[pos..start].to_vec()));
            }
            pos = pos.max(end);
        }
        if pos < file.len() {
            filler.push((pos, file[pos..].to_vec()));
        }
        // All-zero filler is what a fresh buffer holds anyway.
        filler.retain(|(_, bytes)| bytes.iter().any(|&b| b != 0));
        Layout {
            total_len: file.len(),
            segments,
            filler,
        }
    }
}

/// Offsets for segments of the given lengths: the recorded ones when every length still matches,
/// else a fresh sequential layout after the header, each segment 4-byte aligned.
pub fn place(layout: Option<&Layout>, header_len: usize, lens: &[usize]) -> Placement {
    if let Some(l) = layout
        && l.segments.len() == lens.len()
        && l.segments.iter().zip(lens).all(|(s, &len)| s.1 == len)
    {
        return Placement {
            offsets: l.segments.iter().map(|s| s.0).collect(),
            total_len: l.total_len,
            filler: l.filler.clone(),
        };
    }
    let mut offsets = Vec::with_capacity(lens.len());
    let mut pos = header_len;
    for &len in lens {
        pos = pos.next_multiple_of(4);
        offsets.push(pos);
        pos += len;
    }
    Placement {
        offsets,
        total_len: pos,
        filler: Vec::new(),
    }
}

/// Where each segment goes and how long the file is.
pub struct Placement {
    pub offsets: Vec<usize>,
    pub total_len: usize,
    filler: Vec<(usize, Vec<u8>)>,
}

impl Placement {
    /// Assemble the file: header first, then every segment at its offset.
    pub fn assemble(&self, header: &[u8], segments: &[&[u8]]) -> Vec<u8> {
        let end = self
            .offsets
            .iter()
            .zip(segments)
            .map(|(o, s)| o + s.len())
            .max()
            .unwrap_or(0)
            .max(self.total_len)
            .max(header.len());
        let mut out = vec![0u8; end];
        for (offset, bytes) in &self.filler {
            if let Some(dst) = out.get_mut(*offset..offset + bytes.len()) {
                dst.copy_from_slice(bytes);
            }
        }
        out[..header.len()].copy_from_slice(header);
        for (&o, s) in self.offsets.iter().zip(segments) {
            out[o..o + s.len()].copy_from_slice(s);
        }
        out
    }
}
