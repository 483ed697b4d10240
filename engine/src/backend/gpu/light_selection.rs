//! Spatial light selection's tables in the parameter buffer, as
//! `wgsl/light_selection.wgsl` reads them: the CPU's
//! [`SpatialTables`](crate::extract::SpatialTables) laid out in 32-bit
//! words, so the GPU chooses lights by the same bounds, in the same order,
//! with the same arithmetic as [`LightTable::select_at`] and
//! [`LightTable::pmf_at`].
//!
//! Layout (offsets absolute in the parameter buffer):
//!
//! * a head of [`HEAD_WORDS`]: bounded count, unbounded count, their share
//!   (f32), whether the records are a tree, the first bounded light (the
//!   CPU's light for a failed choice), where the unbounded lights, the
//!   per-light entries and the records start;
//! * the unbounded lights' indices;
//! * per light, [`ENTRY_WORDS`]: its slot among the bounded lights (or
//!   [`UNBOUNDED`], or [`UNSELECTED`] for a bounded light without power),
//!   and under a tree its branch bits (low, high word) and leaf depth;
//! * [`RECORD_WORDS`] per record — the bounded lights in their order, or
//!   the tree's nodes root first: min, φ, max, cos θo, axis, cos θe,
//!   two-sided, index (a leaf's light, an interior node's second child),
//!   leaf flag.

use crate::extract::LightTable;
use radiant_core::LightBounds;

/// Words of the head.
const HEAD_WORDS: usize = 8;
/// Words per light entry.
const ENTRY_WORDS: usize = 4;
/// Words per record.
const RECORD_WORDS: usize = 16;
/// A light entry's slot word for a light without bounds.
const UNBOUNDED: u32 = 0xffff_fffe;
/// A light entry's slot word for a light spatial selection never picks.
const UNSELECTED: u32 = u32::MAX;

/// The record of `bounds` with its index word and leaf flag.
fn record(b: &LightBounds, index: u32, leaf: bool) -> [u32; RECORD_WORDS] {
    let f = |v: f32| v.to_bits();
    [
        f(b.min.x),
        f(b.min.y),
        f(b.min.z),
        f(b.phi),
        f(b.max.x),
        f(b.max.y),
        f(b.max.z),
        f(b.cos_theta_o),
        f(b.axis.x),
        f(b.axis.y),
        f(b.axis.z),
        f(b.cos_theta_e),
        u32::from(b.two_sided),
        index,
        u32::from(leaf),
        0,
    ]
}

/// The tables of `table`'s spatial selection, placed at word `at` of the
/// parameter buffer; `None` where the table does not choose spatially.
pub fn words(table: &LightTable, at: usize) -> Option<Vec<u32>> {
    let s = table.spatial()?;
    let n = table.len();
    let unbounded_at = at + HEAD_WORDS;
    let entries_at = unbounded_at + s.unbounded.len();
    let records_at = entries_at + ENTRY_WORDS * n;
    let first = s.bounded.first().map_or(0, |(i, _)| *i);
    let mut w = vec![
        s.bounded.len() as u32,
        s.unbounded.len() as u32,
        s.p_unbounded.to_bits(),
        u32::from(s.tree.is_some()),
        first,
        unbounded_at as u32,
        entries_at as u32,
        records_at as u32,
    ];
    w.extend_from_slice(s.unbounded);
    let mut entries = vec![[UNSELECTED, 0, 0, 0]; n];
    for &i in s.unbounded {
        entries[i as usize][0] = UNBOUNDED;
    }
    for (slot, (i, _)) in s.bounded.iter().enumerate() {
        let (bits, depth) = s.tree.and_then(|t| t.trail(slot)).unwrap_or((0, 0));
        entries[*i as usize] = [slot as u32, bits as u32, (bits >> 32) as u32, depth];
    }
    w.extend(entries.iter().flatten());
    match s.tree {
        Some(tree) => {
            for node in tree.nodes() {
                // Leaves name the light itself rather than its slot.
                let index = if node.leaf {
                    s.bounded[node.index as usize].0
                } else {
                    node.index
                };
                w.extend(record(&node.bounds, index, node.leaf));
            }
        }
        None => {
            for (i, b) in s.bounded {
                w.extend(record(b, *i, true));
            }
        }
    }
    Some(w)
}
