//! [`HvlGrid`]: how the RSM is cut into exactly M cells, one HVL each (paper 003 §5.2 as
//! shine builds it; see the module doc of `passes::hvl`).

/// How the S×S RSM is cut into exactly M cells, one HVL each: R rows of equal height, row j
/// holding the cells `row_start(j)..row_start(j + 1)` (`row_start(j) = ⌊j M / R⌋`) of equal
/// width. The GLSL twin is in `shaders/hvl_cache.comp`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HvlGrid {
    /// Number of cells M.
    pub count: u32,
    /// Number of rows R.
    pub rows: u32,
    /// RSM side S.
    pub size: u32,
}

impl HvlGrid {
    /// The grid of `count` cells over an RSM of side `size`: R = round(√M), raised so that no
    /// row holds more than S cells and lowered to at most S rows; `None` when M > S².
    pub fn new(count: u32, size: u32) -> Option<Self> {
        if count == 0 || size == 0 || u64::from(count) > u64::from(size) * u64::from(size) {
            return None;
        }
        let rows = ((f64::from(count).sqrt().round()) as u32)
            .max(count.div_ceil(size))
            .min(size);
        Some(Self { count, rows, size })
    }

    /// First cell of row `j` (`j ≤ R`; `row_start(R) = M`).
    pub fn row_start(&self, j: u32) -> u32 {
        (u64::from(j) * u64::from(self.count) / u64::from(self.rows)) as u32
    }

    /// The row of cell `m`: `⌈(m + 1) R / M⌉ - 1`.
    pub fn row_of(&self, m: u32) -> u32 {
        ((u64::from(m + 1) * u64::from(self.rows)).div_ceil(u64::from(self.count)) - 1) as u32
    }

    /// Cells in row `j`.
    pub fn row_len(&self, j: u32) -> u32 {
        self.row_start(j + 1) - self.row_start(j)
    }

    /// The texel rectangle `[x0, y0]..[x1, y1]` (exclusive) of cell `m`.
    pub fn cell(&self, m: u32) -> ([u32; 2], [u32; 2]) {
        let j = self.row_of(m);
        let (i, n) = (m - self.row_start(j), self.row_len(j));
        let s = self.size;
        (
            [i * s / n, j * s / self.rows],
            [(i + 1) * s / n, (j + 1) * s / self.rows],
        )
    }

    /// The r1 neighbours of cell `m` (eq. 23's "8-connected neighbours"): the cells beside it in
    /// its row and, in each adjacent row, the cell under its centre and that cell's two
    /// neighbours.
    pub fn neighbours(&self, m: u32) -> Vec<u32> {
        let j = self.row_of(m);
        let ([x0, _], [x1, _]) = self.cell(m);
        let mut out = Vec::with_capacity(8);
        for dj in [-1i64, 0, 1] {
            let jj = i64::from(j) + dj;
            if jj < 0 || jj >= i64::from(self.rows) {
                continue;
            }
            let jj = jj as u32;
            let n = self.row_len(jj);
            // The cell of row jj under the centre (x0 + x1) / 2 of cell m.
            let c = if dj == 0 {
                m - self.row_start(j)
            } else {
                ((x0 + x1) * n / (2 * self.size)).min(n - 1)
            };
            for di in [-1i64, 0, 1] {
                let ii = i64::from(c) + di;
                if (dj == 0 && di == 0) || ii < 0 || ii >= i64::from(n) {
                    continue;
                }
                out.push(self.row_start(jj) + ii as u32);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every texel lies in exactly one cell, every cell holds a texel, rows are found back
    /// from cell indices, and a square count is the regular K×K grid with 8-neighbourhoods.
    #[test]
    fn grid_cells_partition_the_rsm() {
        for (count, size) in [
            (64, 8),
            (64, 16),
            (70, 16),
            (255, 16),
            (256, 16),
            (1000, 40),
        ] {
            let grid = HvlGrid::new(count, size).unwrap();
            let mut owner = vec![u32::MAX; (size * size) as usize];
            for m in 0..count {
                let j = grid.row_of(m);
                assert!(
                    grid.row_start(j) <= m && m < grid.row_start(j + 1),
                    "{count} {m}"
                );
                let (lo, hi) = grid.cell(m);
                assert!(lo[0] < hi[0] && lo[1] < hi[1], "{count}: cell {m} is empty");
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        let t = &mut owner[(y * size + x) as usize];
                        assert_eq!(*t, u32::MAX, "{count}: texel ({x}, {y}) in two cells");
                        *t = m;
                    }
                }
                let n = grid.neighbours(m);
                assert!(!n.contains(&m) && n.iter().all(|&q| q < count));
            }
            assert!(
                owner.iter().all(|&m| m != u32::MAX),
                "{count}: texel in no cell"
            );
        }
        let square = HvlGrid::new(64, 16).unwrap();
        assert_eq!(square.rows, 8);
        assert_eq!(square.cell(9), ([2, 2], [4, 4]));
        let mut n = square.neighbours(9);
        n.sort_unstable();
        assert_eq!(n, [0, 1, 2, 8, 10, 16, 17, 18]);
        assert_eq!(square.neighbours(0).len(), 3);
        assert!(HvlGrid::new(257, 16).is_none());
        assert!(HvlGrid::new(0, 16).is_none());
    }
}
