//! Items grouped by body, each body's in the order they were given (a counting sort into one
//! array): what the body-by-body sums of `linear_product` and `friction_scatter`, and the
//! collision phase's contacts per body, read. A body's items in their original order are what
//! lets a sum done body by body keep the bits of the same sum done item by item.

/// Items of type `T` per body: `of(k)` is body k's, in the order given.
#[derive(Debug, Clone, Default)]
pub(crate) struct ByBody<T> {
    /// `items[start[k]..start[k + 1]]` are body k's.
    start: Vec<u32>,
    items: Vec<T>,
}

impl<T: Copy + Default> ByBody<T> {
    /// Groups `pairs` of (body, item) over `n_bodies` bodies. None if there are more items than
    /// u32 indices.
    pub(crate) fn new(n_bodies: usize, pairs: &[(usize, T)]) -> Option<Self> {
        u32::try_from(pairs.len()).ok()?;
        let mut start = vec![0u32; n_bodies + 1];
        for &(k, _) in pairs {
            start[k + 1] += 1;
        }
        for k in 0..n_bodies {
            start[k + 1] += start[k];
        }
        let mut next = start.clone();
        let mut items = vec![T::default(); pairs.len()];
        for &(k, item) in pairs {
            items[next[k] as usize] = item;
            next[k] += 1;
        }
        Some(Self { start, items })
    }

    /// Body k's items.
    #[inline]
    pub(crate) fn of(&self, k: usize) -> &[T] {
        &self.items[self.start[k] as usize..self.start[k + 1] as usize]
    }

    /// Number of bodies.
    pub(crate) fn n_bodies(&self) -> usize {
        self.start.len() - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each body gets its items in the order given; bodies without items get none.
    #[test]
    fn items_keep_their_order_within_each_body() {
        let pairs = [(2, 'a'), (0, 'b'), (2, 'c'), (3, 'd'), (0, 'e'), (2, 'f')];
        let by = ByBody::new(5, &pairs).expect("few items");
        assert_eq!(by.n_bodies(), 5);
        assert_eq!(by.of(0), ['b', 'e']);
        assert!(by.of(1).is_empty() && by.of(4).is_empty());
        assert_eq!(by.of(2), ['a', 'c', 'f']);
        assert_eq!(by.of(3), ['d']);
    }
}
