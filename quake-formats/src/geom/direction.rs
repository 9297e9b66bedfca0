use glam::DVec3;

/// The two vector operations whose tolerance is ours rather than glam's.
///
/// glam's `try_normalize` multiplies by the reciprocal length and accepts any finite one; plane
/// normals here divide by the length and refuse lengths under 1e-12, as they always did, so the
/// bits of every plane (and every output file) stay what they were. `near` is a strict per-axis
/// test, where glam's `abs_diff_eq` accepts a difference equal to the tolerance.
pub trait DVec3Ext {
    /// The unit vector in this direction, or `None` for a (near) zero vector.
    fn normalized(self) -> Option<DVec3>;
    /// The length and [`DVec3Ext::normalized`] direction, from one square root.
    fn length_and_direction(self) -> Option<(f64, DVec3)>;
    /// True when every component differs by less than `eps`.
    fn near(self, o: DVec3, eps: f64) -> bool;
}

impl DVec3Ext for DVec3 {
    #[inline]
    fn normalized(self) -> Option<DVec3> {
        self.length_and_direction().map(|(_, d)| d)
    }

    #[inline]
    fn length_and_direction(self) -> Option<(f64, DVec3)> {
        let len = self.length();
        (len > 1e-12).then(|| (len, self / len))
    }

    #[inline]
    fn near(self, o: DVec3, eps: f64) -> bool {
        (self - o).abs().cmplt(DVec3::splat(eps)).all()
    }
}
