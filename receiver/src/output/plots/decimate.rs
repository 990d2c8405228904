//! [`Decimated`]: a series kept in bounded memory however long the run.

/// Keeps every `stride`-th value pushed, doubling the stride (and dropping every other value
/// kept) whenever `2 cap` values are held: at most `2 cap` values, evenly spaced in push
/// order, the first value always kept.
#[derive(Debug, Clone)]
pub struct Decimated<T> {
    cap: usize,
    stride: usize,
    pushed: usize,
    values: Vec<T>,
}

impl<T> Decimated<T> {
    /// An empty series holding at most `2 cap` values (`cap` at least 1).
    pub fn new(cap: usize) -> Self {
        Self {
            cap: cap.max(1),
            stride: 1,
            pushed: 0,
            values: Vec::new(),
        }
    }

    /// Offers the next value.
    pub fn push(&mut self, v: T) {
        if self.pushed.is_multiple_of(self.stride) {
            self.values.push(v);
            if self.values.len() >= 2 * self.cap {
                let mut k = 0;
                self.values.retain(|_| {
                    k += 1;
                    k % 2 == 1
                });
                self.stride *= 2;
            }
        }
        self.pushed += 1;
    }

    /// The values kept, in push order.
    pub fn values(&self) -> &[T] {
        &self.values
    }

    /// Keep one value of every this many pushed.
    pub fn stride(&self) -> usize {
        self.stride
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounded_and_evenly_spaced() {
        let mut d = Decimated::new(100);
        for i in 0..1_000_000u32 {
            d.push(i);
        }
        let v = d.values();
        assert!(v.len() < 200 && v.len() >= 100, "{} kept", v.len());
        assert_eq!(v[0], 0);
        let stride = d.stride() as u32;
        assert!(v.windows(2).all(|w| w[1] - w[0] == stride));
        // The end of the run is represented: the last value kept is within one stride of it.
        assert!(999_999 - v[v.len() - 1] < stride);
    }

    #[test]
    fn short_series_are_kept_whole() {
        let mut d = Decimated::new(10);
        (0..15).for_each(|i| d.push(i));
        assert_eq!(d.values(), (0..15).collect::<Vec<_>>().as_slice());
    }
}
