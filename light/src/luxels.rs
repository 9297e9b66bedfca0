//! From a face's light per sample to its light per luxel.
//!
//! A run lights `per_axis²` samples in each luxel, and those samples make one image: the face's
//! oversampled grid, `per_axis` times as wide and as tall as its lightmap. Light turns that image
//! into luxels as ericw-tools does, in three steps:
//!
//! 1. **Fill.** A sample inside solid (occluded) has no light of its own. It takes the mean of its
//!    open neighbours (the eight around it). The image is filled in place, row by row, so a sample
//!    filled early in a pass lends its value to the ones after it; passes repeat until every
//!    sample is open. A face whose every sample is occluded is left as it is.
//! 2. **Blur** (`--soft`). Each sample becomes the mean of the square of samples within the
//!    radius, reading past the image's edge as its nearest edge sample.
//! 3. **Average.** Each luxel is the mean of its samples.
//!
//! The reference ([`ToLuxels::OpenMeans`]) measures light, not ericw-tools' bytes: a luxel is the
//! mean of its open samples only, a luxel with none takes the mean of its neighbours', and it
//! is not blurred. [`soften_luxels`] puts finished luxels through a run's blur, to compare a run
//! that blurs with a reference that does not.

/// How a face's samples become luxels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToLuxels {
    /// Occluded samples filled, the image blurred `soft_radius` samples each way, then luxel
    /// means, as ericw-tools writes them.
    AsEricw { soft_radius: usize },
    /// Each luxel the mean of its open samples (the reference).
    OpenMeans,
}

/// A face's light on its oversampled grid, row by row.
struct SampleImage {
    width: usize,
    height: usize,
    values: Vec<[f32; 3]>,
}

impl SampleImage {
    /// The image of `samples` given luxel by luxel (row-major), `per_axis²` to a luxel in
    /// row-major order, on a lightmap `luxel_width` wide.
    fn from_luxel_order<T: Copy + Default>(
        samples: &[T],
        luxel_width: usize,
        per_axis: usize,
    ) -> (usize, usize, Vec<T>) {
        let per = per_axis * per_axis;
        let width = luxel_width * per_axis;
        let height = samples.len() / per / luxel_width.max(1) * per_axis;
        let mut out = vec![T::default(); samples.len()];
        // Each row of a luxel's samples is a run of one of the image's rows.
        for (luxel, block) in samples.chunks_exact(per).enumerate() {
            let (x, y) = (
                (luxel % luxel_width) * per_axis,
                (luxel / luxel_width) * per_axis,
            );
            for (sub_row, run) in block.chunks_exact(per_axis).enumerate() {
                let at = (y + sub_row) * width + x;
                out[at..at + per_axis].copy_from_slice(run);
            }
        }
        (width, height, out)
    }

    fn of_samples(samples: &[[f32; 3]], luxel_width: usize, per_axis: usize) -> SampleImage {
        let (width, height, values) = Self::from_luxel_order(samples, luxel_width, per_axis);
        SampleImage {
            width,
            height,
            values,
        }
    }

    /// Fills the samples not `open` from their open neighbours (step 1 of the module doc).
    fn fill(&mut self, mut open: Vec<bool>) {
        let (w, h) = (self.width, self.height);
        loop {
            let mut filled_any = false;
            let mut left = false;
            for y in 0..h {
                for x in 0..w {
                    if open[y * w + x] {
                        continue;
                    }
                    let mut acc = [0.0f32; 3];
                    let mut count = 0.0f32;
                    for ny in y.saturating_sub(1)..(y + 2).min(h) {
                        for nx in x.saturating_sub(1)..(x + 2).min(w) {
                            if open[ny * w + nx] {
                                let v = self.values[ny * w + nx];
                                for k in 0..3 {
                                    acc[k] += v[k];
                                }
                                count += 1.0;
                            }
                        }
                    }
                    if count > 0.0 {
                        self.values[y * w + x] = acc.map(|a| a / count);
                        open[y * w + x] = true;
                        filled_any = true;
                    } else {
                        left = true;
                    }
                }
            }
            if !left || !filled_any {
                return;
            }
        }
    }

    /// Box-blurs the image `radius` samples each way, edges clamped (step 2). The clamped box
    /// is separable: rows, then columns. Each sample sums its taps in the same order (the
    /// nearest edge sample standing in for those past it), tap by tap over a whole row at once,
    /// then over whole runs of rows.
    fn blur(&mut self, radius: usize) {
        if radius == 0 || self.values.is_empty() {
            return;
        }
        crate::simd::widest(
            #[inline(always)]
            || self.blur_any(radius),
        );
    }

    /// [`SampleImage::blur`] for whatever the build targets.
    #[inline(always)]
    fn blur_any(&mut self, radius: usize) {
        let (w, h) = (self.width, self.height);
        let taps = (2 * radius + 1) as f32;
        let add = |acc: &mut [f32], v: &[f32]| {
            for (a, v) in acc.iter_mut().zip(v) {
                *a += v;
            }
        };
        let mut rows = vec![[0.0f32; 3]; w * h];
        // A row with `radius` copies of its edge samples on either side: tap d of sample x
        // reads sample x + d of it, the row's sample x + d - radius held to the row.
        let mut padded = vec![[0.0f32; 3]; w + 2 * radius];
        for (src, dst) in self.values.chunks_exact(w).zip(rows.chunks_exact_mut(w)) {
            let (left, rest) = padded.split_at_mut(radius);
            let (middle, right) = rest.split_at_mut(w);
            left.fill(src[0]);
            middle.copy_from_slice(src);
            right.fill(src[w - 1]);
            for d in 0..=2 * radius {
                add(dst.as_flattened_mut(), padded[d..][..w].as_flattened());
            }
            for a in dst.as_flattened_mut() {
                *a /= taps;
            }
        }
        // Tap d of row y reads row y + d - radius, held to the image: the rows between the
        // held ones are read as one run, the image's rows being consecutive.
        let row = 3 * w;
        let (sums, rows) = (self.values.as_flattened_mut(), rows.as_flattened());
        sums.fill(0.0);
        for d in 0..=2 * radius {
            let first = radius.saturating_sub(d).min(h);
            let end = (h + radius).saturating_sub(d).clamp(first, h);
            for y in 0..first {
                add(&mut sums[y * row..][..row], &rows[..row]);
            }
            if end > first {
                let (from, run) = (first + d - radius, (end - first) * row);
                add(&mut sums[first * row..][..run], &rows[from * row..][..run]);
            }
            for y in end..h {
                add(&mut sums[y * row..][..row], &rows[(h - 1) * row..][..row]);
            }
        }
        for a in sums {
            *a /= taps;
        }
    }

    /// Each luxel's mean of its `per_axis²` samples, row by row (step 3).
    fn luxel_means(&self, per_axis: usize) -> Vec<[f32; 3]> {
        let (lw, lh) = (self.width / per_axis, self.height / per_axis);
        let n = (per_axis * per_axis) as f32;
        let mut out = Vec::with_capacity(lw * lh);
        for ly in 0..lh {
            for lx in 0..lw {
                let mut acc = [0.0f32; 3];
                for y in ly * per_axis..(ly + 1) * per_axis {
                    for v in &self.values[y * self.width + lx * per_axis..][..per_axis] {
                        for k in 0..3 {
                            acc[k] += v[k];
                        }
                    }
                }
                out.push(acc.map(|a| a / n));
            }
        }
        out
    }
}

/// Luxel means of `samples` (luxel by luxel, `per_axis²` each) on a lightmap `luxel_width`
/// wide, as ericw-tools makes them: occluded samples filled, blurred `soft_radius` samples
/// each way, averaged. `occluded` is empty when no sample is.
pub fn ericw_luxels(
    samples: &[[f32; 3]],
    occluded: &[bool],
    luxel_width: usize,
    per_axis: usize,
    soft_radius: usize,
) -> Vec<[f32; 3]> {
    let mut image = SampleImage::of_samples(samples, luxel_width, per_axis);
    if occluded.contains(&true) {
        let open: Vec<bool> = occluded.iter().map(|&o| !o).collect();
        let (_, _, open) = SampleImage::from_luxel_order(&open, luxel_width, per_axis);
        image.fill(open);
    }
    image.blur(soft_radius);
    image.luxel_means(per_axis)
}

/// `luxels` (`width` wide) through a run's `--soft` blur: each luxel spread over `per_axis²`
/// samples, blurred `soft_radius` samples each way, averaged back.
pub fn soften_luxels(
    luxels: &[[f32; 3]],
    width: usize,
    per_axis: usize,
    soft_radius: usize,
) -> Vec<[f32; 3]> {
    let per = per_axis * per_axis;
    let samples: Vec<[f32; 3]> = luxels
        .iter()
        .flat_map(|&l| std::iter::repeat_n(l, per))
        .collect();
    ericw_luxels(&samples, &[], width, per_axis, soft_radius)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: &[f32]) -> Vec<[f32; 3]> {
        v.iter().map(|&x| [x; 3]).collect()
    }

    #[test]
    fn samples_are_laid_out_luxel_by_luxel() {
        // Two luxels side by side, 2×2 samples each: 0 1 / 2 3 and 4 5 / 6 7.
        let (w, h, image) = SampleImage::from_luxel_order(&[0, 1, 2, 3, 4, 5, 6, 7], 2, 2);
        assert_eq!((w, h), (4, 2));
        assert_eq!(image, [0, 1, 4, 5, 2, 3, 6, 7]);
    }

    #[test]
    fn occluded_samples_fill_row_by_row_from_the_ones_filled_before() {
        // One row, open only at the left: each sample takes the one filled just before it.
        let mut image = SampleImage {
            width: 4,
            height: 1,
            values: grey(&[8.0, 0.0, 0.0, 0.0]),
        };
        image.fill(vec![true, false, false, false]);
        assert_eq!(image.values, grey(&[8.0; 4]));
        // Open at the right: the first pass fills only the sample beside it, later passes the rest.
        let mut image = SampleImage {
            width: 3,
            height: 1,
            values: grey(&[0.0, 0.0, 6.0]),
        };
        image.fill(vec![false, false, true]);
        assert_eq!(image.values, grey(&[6.0; 3]));
        // Nothing open: left as it is.
        let mut image = SampleImage {
            width: 2,
            height: 1,
            values: grey(&[1.0, 3.0]),
        };
        image.fill(vec![false, false]);
        assert_eq!(image.values, grey(&[1.0, 3.0]));
    }

    #[test]
    fn the_blur_reads_past_the_edge_as_the_edge_sample() {
        let mut image = SampleImage {
            width: 3,
            height: 1,
            values: grey(&[0.0, 0.0, 9.0]),
        };
        image.blur(1);
        // The left sample averages 0, 0, 0 (itself twice); the right 0, 9, 9.
        assert_eq!(image.values, grey(&[0.0, 3.0, 6.0]));
        // A uniform image stays uniform, however wide the radius.
        let mut flat = SampleImage {
            width: 2,
            height: 2,
            values: grey(&[5.0; 4]),
        };
        flat.blur(3);
        assert!(flat.values.iter().all(|v| (v[0] - 5.0).abs() < 1e-6));
    }

    #[test]
    fn a_partly_occluded_luxel_averages_its_filled_samples_too() {
        // One luxel of 2×2 samples, the right column occluded. The top right takes the mean
        // of 4 and 2, then the bottom right that of 4, 3 (filled just before) and 2.
        let samples = grey(&[4.0, 0.0, 2.0, 0.0]);
        let out = ericw_luxels(&samples, &[false, true, false, true], 1, 2, 0);
        assert_eq!(out.len(), 1);
        assert!(
            (out[0][0] - (4.0 + 3.0 + 2.0 + 3.0) / 4.0).abs() < 1e-6,
            "{out:?}"
        );
    }

    #[test]
    fn softening_luxels_with_no_blur_leaves_them() {
        let luxels = grey(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(soften_luxels(&luxels, 2, 4, 0), luxels);
        let soft = soften_luxels(&luxels, 2, 4, 2);
        assert!(soft[0][0] > 1.0 && soft[3][0] < 4.0, "{soft:?}");
    }

    /// The blur as its definition reads: each sample the mean of its clamped taps, summed in
    /// tap order, rows then columns.
    fn blur_by_definition(values: &[[f32; 3]], w: usize, h: usize, r: usize) -> Vec<[f32; 3]> {
        let taps = (2 * r + 1) as f32;
        let mean = |at: &dyn Fn(usize) -> [f32; 3], i: usize, len: usize| {
            let mut acc = [0.0f32; 3];
            for d in 0..=2 * r {
                let v = at((i + d).saturating_sub(r).min(len - 1));
                for k in 0..3 {
                    acc[k] += v[k];
                }
            }
            acc.map(|a| a / taps)
        };
        let rows: Vec<[f32; 3]> = (0..w * h)
            .map(|i| mean(&|x| values[i / w * w + x], i % w, w))
            .collect();
        (0..w * h)
            .map(|i| mean(&|y| rows[y * w + i % w], i / w, h))
            .collect()
    }

    proptest::proptest! {
        /// The blur gives the very bits of its definition, for any size and radius.
        #[test]
        fn blur_matches_its_definition_bit_for_bit(
            w in 1usize..12,
            h in 1usize..12,
            r in 1usize..5,
            seed in proptest::prelude::any::<u64>(),
        ) {
            let mut x = seed | 1;
            let values: Vec<[f32; 3]> = (0..w * h)
                .map(|_| {
                    std::array::from_fn(|_| {
                        x ^= x << 13;
                        x ^= x >> 7;
                        x ^= x << 17;
                        (x % 100_000) as f32 / 7.0
                    })
                })
                .collect();
            let want = blur_by_definition(&values, w, h, r);
            let bits = |v: &[[f32; 3]]| v.iter().flatten().map(|f| f.to_bits()).collect::<Vec<_>>();
            // As each vector build this CPU runs compiles it.
            let each = crate::simd::builds_here(
                #[inline(always)]
                || {
                    let mut image = SampleImage { width: w, height: h, values: values.clone() };
                    image.blur_any(r);
                    image.values
                },
            );
            for (build, blurred) in each {
                proptest::prop_assert_eq!(bits(&blurred), bits(&want), "{:?}", build);
            }
        }
    }
}
