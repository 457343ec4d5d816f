//! The thesis's hash table: the children of every subdivided box, keyed by
//! the box's decimal name (name mod table size, chained), which only the
//! thesis's walk reads.

use super::*;

impl<C: OctreeCapacities, const FRAMES: usize> Octree<C, FRAMES> {
    pub(super) fn insert_entry(&mut self, name: u64, children: u32) {
        let none = C::Index::new(C::Index::MAX);
        let index = C::Index::new(self.entries.as_slice().len() as u32);
        let _ = self.entries.push(HashEntry { name, children: C::Index::new(children), next: none });
        let bucket = (name % self.buckets.as_slice().len() as u64) as usize;
        // Append at the end of the bucket's chain, as the thesis does.
        let mut at = self.buckets.as_slice()[bucket];
        if at == none {
            self.buckets.as_mut_slice()[bucket] = index;
            return;
        }
        loop {
            let next = self.entries.as_slice()[at.get() as usize].next;
            if next == none {
                self.entries.as_mut_slice()[at.get() as usize].next = index;
                return;
            }
            at = next;
        }
    }

    pub(super) fn finish(&mut self, max_depth: u32) {
        let nodes = self.nodes.as_slice();
        self.report.nodes = nodes.len();
        self.report.leaves = nodes.iter().filter(|n| !n.is_internal()).count();
        self.report.references = self.refs.as_slice().len();
        self.report.hash_entries = self.entries.as_slice().len();
        self.report.depth = self.root_log2.saturating_sub(self.min_log2).min(max_depth);
        self.report.bytes = core::mem::size_of_val(nodes)
            + core::mem::size_of_val(self.refs.as_slice())
            + core::mem::size_of_val(self.shafts.as_slice())
            + core::mem::size_of_val(self.entries.as_slice())
            + core::mem::size_of_val(self.buckets.as_slice());
    }

    /// The children of the box called `name`, looked up in the hash table.
    pub(super) fn lookup(&self, name: u64) -> Option<u32> {
        let buckets = self.buckets.as_slice();
        let mut at = buckets.get((name % buckets.len().max(1) as u64) as usize)?.get();
        while at != C::Index::MAX {
            let e = self.entries.as_slice().get(at as usize)?;
            if e.name == name {
                return Some(e.children.get());
            }
            at = e.next.get();
        }
        None
    }
}
