//! Counting sort of batch slots by a small key (material, light), the
//! "coherent shading" step of sorted deferred shading.

/// Reorders `items` by `key(item)` (stable), given `keys` distinct keys, and
/// writes into `offsets` the start of each key's range (length `keys + 1`).
/// `scratch` and `cursor` are reusable buffers.
pub(crate) fn sort_by_key(
    items: &mut Vec<u32>,
    scratch: &mut Vec<u32>,
    cursor: &mut Vec<u32>,
    offsets: &mut Vec<u32>,
    keys: usize,
    key: impl Fn(u32) -> u32,
) {
    offsets.clear();
    offsets.resize(keys + 1, 0);
    if keys == 0 {
        // No keys (a scene without materials): nothing can be sorted.
        debug_assert!(items.is_empty(), "items need keys");
        return;
    }
    let counts = &mut offsets[..];
    for &i in items.iter() {
        counts[key(i) as usize + 1] += 1;
    }
    for k in 0..keys {
        offsets[k + 1] += offsets[k];
    }
    if offsets[1] as usize == items.len() {
        return; // everything has key 0: already sorted
    }
    scratch.clear();
    scratch.resize(items.len(), 0);
    cursor.clear();
    cursor.extend_from_slice(&offsets[..keys]);
    let (sorted, cursor) = (&mut scratch[..], &mut cursor[..]);
    for &i in items.iter() {
        let k = key(i) as usize;
        sorted[cursor[k] as usize] = i;
        cursor[k] += 1;
    }
    std::mem::swap(items, scratch);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorts_stably_and_reports_ranges() {
        let keys = [2u32, 0, 1, 2, 0, 1, 1];
        let mut items: Vec<u32> = (0..7).collect();
        let (mut scratch, mut cursor, mut offsets) = (Vec::new(), Vec::new(), Vec::new());
        sort_by_key(
            &mut items,
            &mut scratch,
            &mut cursor,
            &mut offsets,
            3,
            |i| keys[i as usize],
        );
        assert_eq!(items, [1, 4, 2, 5, 6, 0, 3]);
        assert_eq!(offsets, [0, 2, 5, 7]);
    }

    #[test]
    fn no_keys_and_no_items_leave_one_empty_offset() {
        let (mut items, mut scratch, mut cursor) = (Vec::new(), Vec::new(), Vec::new());
        let mut offsets = vec![9, 9];
        sort_by_key(
            &mut items,
            &mut scratch,
            &mut cursor,
            &mut offsets,
            0,
            |_| 0,
        );
        assert!(items.is_empty());
        assert_eq!(offsets, [0]);
    }
}
