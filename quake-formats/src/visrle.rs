//! Quake's zero-run compression of one PVS row: non-zero bytes are stored as they are; a run of
//! zero bytes is stored as a zero followed by the run length (1..=255).

/// Compress one row of `(leafs + 7) / 8` bytes.
pub fn compress_row(row: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(row.len());
    let mut i = 0;
    while i < row.len() {
        if row[i] != 0 {
            out.push(row[i]);
            i += 1;
            continue;
        }
        let mut run = 0usize;
        while i < row.len() && row[i] == 0 && run < 255 {
            run += 1;
            i += 1;
        }
        out.push(0);
        out.push(run as u8);
    }
    out
}

/// Decompress a row of `row_len` bytes from the start of `data`. Engines read past the row's end
/// into the next one when data is short; we stop and return what was decoded, padded with zeros,
/// plus whether the data was complete.
pub fn decompress_row(data: &[u8], row_len: usize) -> (Vec<u8>, bool) {
    let mut out = Vec::with_capacity(row_len);
    let mut i = 0;
    while out.len() < row_len {
        let Some(&b) = data.get(i) else {
            out.resize(row_len, 0);
            return (out, false);
        };
        i += 1;
        if b != 0 {
            out.push(b);
            continue;
        }
        let Some(&run) = data.get(i) else {
            out.resize(row_len, 0);
            return (out, false);
        };
        i += 1;
        let run = (run as usize).min(row_len - out.len());
        out.resize(out.len() + run, 0);
    }
    (out, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn long_zero_runs_split_at_255() {
        let row = vec![0u8; 600];
        assert_eq!(compress_row(&row), vec![0, 255, 0, 255, 0, 90]);
    }

    #[test]
    fn truncated_data_is_reported() {
        let (row, complete) = decompress_row(&[0xff, 0], 4);
        assert_eq!(row, vec![0xff, 0, 0, 0]);
        assert!(!complete);
    }

    proptest! {
        #[test]
        fn round_trip(row in proptest::collection::vec(prop_oneof![Just(0u8), any::<u8>()], 0..700)) {
            let packed = compress_row(&row);
            let (back, complete) = decompress_row(&packed, row.len());
            prop_assert!(complete);
            prop_assert_eq!(back, row);
        }
    }
}
