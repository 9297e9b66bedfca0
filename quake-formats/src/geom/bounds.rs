use glam::DVec3;

/// An axis-aligned box; empty until a point is added.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Lowest corner; +infinity on every axis while empty.
    pub mins: DVec3,
    /// Highest corner; -infinity on every axis while empty.
    pub maxs: DVec3,
}

impl Default for Bounds {
    fn default() -> Self {
        Bounds::EMPTY
    }
}

impl Bounds {
    /// The box of no points: inside out, so that adding any point makes it that point.
    pub const EMPTY: Bounds = Bounds {
        mins: DVec3::INFINITY,
        maxs: DVec3::NEG_INFINITY,
    };

    /// Whether no point has been added (`mins` above `maxs` on some axis).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.mins.x > self.maxs.x || self.mins.y > self.maxs.y || self.mins.z > self.maxs.z
    }

    /// Grow the box to hold `p`.
    #[inline]
    pub fn add_point(&mut self, p: DVec3) {
        self.mins = per_axis(self.mins, p, f64::min);
        self.maxs = per_axis(self.maxs, p, f64::max);
    }

    /// The smallest box holding both boxes.
    #[inline]
    pub fn union(&self, o: &Bounds) -> Bounds {
        Bounds {
            mins: per_axis(self.mins, o.mins, f64::min),
            maxs: per_axis(self.maxs, o.maxs, f64::max),
        }
    }

    /// Whether `p` is inside or on the box.
    #[inline]
    pub fn contains(&self, p: DVec3) -> bool {
        (0..3).all(|i| p[i] >= self.mins[i] && p[i] <= self.maxs[i])
    }

    /// Whether the two boxes overlap or touch.
    #[inline]
    pub fn intersects(&self, o: &Bounds) -> bool {
        (0..3).all(|i| self.mins[i] <= o.maxs[i] && o.mins[i] <= self.maxs[i])
    }

    /// The middle of the box (meaningless while empty).
    #[inline]
    pub fn center(&self) -> DVec3 {
        (self.mins + self.maxs) * 0.5
    }
}

/// `f` on each axis. Bounds use `f64::min`/`max`, not glam's `DVec3::min`/`max` (a `<` select):
/// the two keep different zeros when -0.0 meets 0.0, and a model's bounds are written to the
/// file with their sign.
#[inline]
fn per_axis(a: DVec3, b: DVec3, f: impl Fn(f64, f64) -> f64) -> DVec3 {
    DVec3::new(f(a.x, b.x), f(a.y, b.y), f(a.z, b.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_negative_zero_bound_keeps_its_sign() {
        // Regression: the move to glam changed a model's mins from -0.0 to 0.0 (demo.map).
        let mut b = Bounds::EMPTY;
        b.add_point(DVec3::new(1.0, 1.0, -0.0));
        b.add_point(DVec3::new(2.0, 2.0, 0.0));
        assert!(b.mins.z.is_sign_negative(), "{:?}", b.mins);
        let u = Bounds::EMPTY.union(&b);
        assert!(u.mins.z.is_sign_negative(), "{:?}", u.mins);
    }
}
