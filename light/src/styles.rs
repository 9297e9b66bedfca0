//! Light kept per light style: short lists of `(style, value)` pairs, in the order the styles
//! were first met (a face takes at most four styles, a map a few dozen: a scan beats hashing).

/// The value of `style` in `list`, added as `dark()` makes it when the list has none yet.
pub fn entry<T>(list: &mut Vec<(u8, T)>, style: u8, dark: impl FnOnce() -> T) -> &mut T {
    let k = match list.iter().position(|(s, _)| *s == style) {
        Some(k) => k,
        None => {
            list.push((style, dark()));
            list.len() - 1
        }
    };
    &mut list[k].1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_style_is_added_once_in_the_order_first_met() {
        let mut list: Vec<(u8, u32)> = Vec::new();
        *entry(&mut list, 5, || 0) += 2;
        *entry(&mut list, 0, || 10) += 1;
        *entry(&mut list, 5, || unreachable!("style 5 is there")) += 3;
        assert_eq!(list, [(5, 5), (0, 11)]);
    }
}
