//! Writing a light buffer's words for a scene, reading them back, and
//! checking words built elsewhere against the scene.

use super::cells::{footprint, needs, Footprint, Needs};
use super::{LightBuffer, LightBufferError, Words, MARGIN, MAX_LEVEL, OBJECT_BITS, OBJECT_MASK};
use crate::capacity::Arena;
use crate::scene::SceneView;

/// A light's cube as the build and the check read it from the words.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cube {
    pub(super) light: [i64; 3],
    /// The cell of the light's own list.
    pub(super) own: usize,
    /// Per face: its first cell and its rectangle's word.
    pub(super) faces: [(usize, u32); 6],
}

impl Cube {
    pub(super) fn read(words: &[u32]) -> Cube {
        Cube {
            light: [0, 1, 2].map(|a| words[a] as i32 as i64),
            own: words[3] as usize,
            faces: core::array::from_fn(|f| (words[4 + 2 * f] as usize, words[5 + 2 * f])),
        }
    }

    /// The cell of cell `(i, j)` of face `face`, if its rectangle holds it.
    pub(super) fn cell(&self, face: usize, i: u32, j: u32) -> Option<usize> {
        let (first, rect) = self.faces[face];
        cell_in(first, rect, i, j)
    }
}

/// A face's rectangle of cells as a word: its first cells and its sides
/// along the face's two axes (sides 0: no cell).
pub(super) const fn rect_word(low: [u8; 2], size: [u8; 2]) -> u32 {
    low[0] as u32 | (low[1] as u32) << 8 | (size[0] as u32) << 16 | (size[1] as u32) << 24
}

/// The cell of cell `(i, j)` in the rectangle `rect` whose first cell is
/// `first`, if the rectangle holds it (rows along the first axis).
#[inline(always)]
pub(super) fn cell_in(first: usize, rect: u32, i: u32, j: u32) -> Option<usize> {
    let (i, j) = (i.wrapping_sub(rect & 0xFF), j.wrapping_sub(rect >> 8 & 0xFF));
    let (rows, columns) = (rect >> 16 & 0xFF, rect >> 24);
    (i < rows && j < columns).then(|| first + (i * columns + j) as usize)
}

/// Calls `each(cell, entry)` for every entry of the lists `cube`'s light
/// needs at `level` (`finest` or coarser).
pub(super) fn for_each_entry(
    scene: &SceneView<'_>,
    cube: &Cube,
    level: u32,
    finest: u32,
    margin: i64,
    mut each: impl FnMut(usize, u32),
) {
    for id in scene.object_ids() {
        match footprint(scene.shape(id).bounds(), cube.light, margin, finest) {
            Footprint::Around => each(cube.own, id.0),
            Footprint::Faces(rects) => {
                for (face, rect) in rects.iter().enumerate() {
                    let Some(rect) = rect.map(|r| r.coarser(finest - level)) else { continue };
                    let entry = rect.depth << OBJECT_BITS | id.0;
                    for i in rect.low[0]..=rect.high[0] {
                        for j in rect.low[1]..=rect.high[1] {
                            if let Some(cell) = cube.cell(face, i as u32, j as u32) {
                                each(cell, entry);
                            }
                        }
                    }
                }
            }
        }
    }
}

impl<'a> LightBuffer<'a> {
    /// [`LightBuffer::build`] for at most the first `lights` lights, with
    /// objects widened by `margin` (tests make it too small).
    pub(crate) fn build_with_margin<W: Arena<u32>>(
        scene: &SceneView<'_>,
        words: &'a mut W,
        cells_a_side: u32,
        lights: usize,
        margin: i64,
    ) -> LightBuffer<'a> {
        words.clear();
        let finest = (31 - cells_a_side.max(1).leading_zeros()).min(MAX_LEVEL);
        let capacity = W::CAPACITY;
        let objects = scene.object_count();
        if scene.lights.is_empty() || objects > OBJECT_MASK as usize + 1 {
            return Self::parse(words.as_slice()).unwrap_or(LightBuffer::NONE);
        }
        // The lights' needs at every level: the finest where all fit, else
        // one cell a face for as many lights as fit.
        let lights = scene.lights.len().min(lights);
        let mut total = Needs::default();
        for light in 0..lights {
            let (needs, _) = needs(scene, light, finest, margin);
            for level in 0..=finest as usize {
                total.cells[level] += needs.cells[level];
                total.entries[level] += needs.entries[level];
            }
        }
        // The cells end with one more: the last list's end.
        let fits = |lights: usize, cells: usize, entries: usize| Words::of(lights, cells + 1, entries) <= capacity;
        let chosen = (0..=finest).rev().find(|&l| fits(lights, total.cells[l as usize], total.entries[l as usize]));
        let (level, lights) = match chosen {
            Some(level) => (level, lights),
            None => {
                let (mut cells, mut entries, mut fitting) = (0, 0, 0);
                for light in 0..lights {
                    let (needs, _) = needs(scene, light, 0, margin);
                    if !fits(fitting + 1, cells + needs.cells[0], entries + needs.entries[0]) {
                        break;
                    }
                    (cells, entries, fitting) = (cells + needs.cells[0], entries + needs.entries[0], fitting + 1);
                }
                (0, fitting)
            }
        };
        if lights == 0 {
            return LightBuffer::NONE;
        }
        // The header and the cubes, then the cells (each a count first)
        // and the entries.
        for word in [Words::MAGIC, lights as u32, level, 0, objects as u32] {
            let _ = words.push(word);
        }
        let mut cell = 0usize;
        for light in 0..lights {
            let (_, faces) = needs(scene, light, finest, margin);
            for c in scene.lights[light].position.bits() {
                let _ = words.push(c as u32);
            }
            let _ = words.push(cell as u32);
            cell += 1;
            for rect in faces {
                let (low, size) = match rect.map(|r| r.coarser(finest - level)) {
                    Some(r) => (r.low, [0, 1].map(|k| r.high[k] - r.low[k] + 1)),
                    None => ([0; 2], [0; 2]),
                };
                let _ = words.push(cell as u32);
                let _ = words.push(rect_word(low, size));
                cell += size[0] as usize * size[1] as usize;
            }
        }
        let cells = cell + 1;
        words.as_mut_slice()[3] = cells as u32;
        for _ in 0..cells {
            let _ = words.push(0);
        }
        let (head, counts) = words.as_mut_slice().split_at_mut(Words::of(lights, 0, 0));
        let cubes = || head[Words::HEADER..].chunks_exact(Words::CUBE).map(Cube::read);
        for cube in cubes() {
            for_each_entry(scene, &cube, level, finest, margin, |cell, _| counts[cell] += 1);
        }
        let mut end = 0;
        for count in counts.iter_mut() {
            end += *count;
            *count = end;
        }
        for _ in 0..end {
            let _ = words.push(0);
        }
        let (head, rest) = words.as_mut_slice().split_at_mut(Words::of(lights, 0, 0));
        let (starts, entries) = rest.split_at_mut(cells);
        let cubes = || head[Words::HEADER..].chunks_exact(Words::CUBE).map(Cube::read);
        for cube in cubes() {
            for_each_entry(scene, &cube, level, finest, margin, |cell, entry| {
                starts[cell] -= 1;
                entries[starts[cell] as usize] = entry;
            });
        }
        for cell in 0..cells - 1 {
            crate::sort::sort_by_key(&mut entries[starts[cell] as usize..starts[cell + 1] as usize], |&e| e);
        }
        Self::parse(words.as_slice()).unwrap_or(LightBuffer::NONE)
    }

    /// The buffer in `words` if its header and sizes are sound.
    pub(super) fn parse(words: &'a [u32]) -> Option<LightBuffer<'a>> {
        if words.first() == Some(&Words::CONES_MAGIC) {
            return Self::parse_cones(words);
        }
        let &[magic, lights, level, cells, _] = words.get(..Words::HEADER)? else { return None };
        let (lights, cells) = (lights as usize, cells as usize);
        let entries = words.len().checked_sub(Words::of(lights, cells, 0))?;
        (magic == Words::MAGIC
            && level <= MAX_LEVEL
            && cells > 0
            && words[Words::of(lights, cells, 0) - 1] as usize == entries)
            .then_some(LightBuffer {
                words,
                lights,
                level: level as u8,
                cells: Words::of(lights, 0, 0),
                entries: Words::of(lights, cells, 0),
                cones: false,
            })
    }

    /// A buffer built beforehand for a scene, after checking that it holds
    /// everything a buffer built for `scene` would: its lights and object
    /// count, and every object in every cell it can be seen in, at a depth
    /// no greater than where it begins. A build script can so keep a
    /// scene's buffer in flash ([`LightBuffer::words`] of one built on the
    /// host) and a board spend no RAM on it.
    ///
    /// ```
    /// use octrace_core::accel::{LightBuffer, LightBufferError};
    /// use octrace_core::parse::parse;
    /// use octrace_core::profile::Board64K;
    /// use octrace_core::scene::Scene;
    ///
    /// let text = "VIEWPOINT -9 -9 -9\nLIGHT 10 9 9 9\nSPHERE 1 1 0 0 0\nSPHERE 1 0.5 2 2 2\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n";
    /// let mut scene = Scene::<Board64K>::new();
    /// parse(text, &mut scene, &mut |e| panic!("{e}")).unwrap();
    /// let mut words = heapless::Vec::<u32, 400>::new();
    /// let built = LightBuffer::build(&scene.view(), &mut words, 8).words().to_vec();
    /// assert!(LightBuffer::verified(&scene.view(), &built).is_ok());
    ///
    /// // The same lights, but the second sphere moved: refused.
    /// let mut other = Scene::<Board64K>::new();
    /// parse(&text.replace("0.5 2 2 2", "0.5 2 -2 2"), &mut other, &mut |e| panic!("{e}")).unwrap();
    /// assert!(matches!(LightBuffer::verified(&other.view(), &built), Err(LightBufferError::Incomplete { .. })));
    /// ```
    pub fn verified(scene: &SceneView<'_>, words: &'a [u32]) -> Result<LightBuffer<'a>, LightBufferError> {
        use LightBufferError::{Incomplete, Malformed, OtherScene};
        let buffer = Self::parse(words).ok_or(Malformed)?;
        if buffer.cones {
            return buffer.verified_cones(scene).map(|()| buffer);
        }
        let (starts, entries) = words[buffer.cells..].split_at(buffer.entries - buffer.cells);
        if buffer.lights > scene.lights.len() || words[4] as usize != scene.object_count() {
            return Err(OtherScene);
        }
        // Every list within the entries and sorted, every object one of the
        // scene's.
        let list = |cell: usize| Some(&entries[*starts.get(cell)? as usize..*starts.get(cell + 1)? as usize]);
        for pair in starts.windows(2) {
            let list = entries.get(pair[0] as usize..pair[1] as usize).ok_or(Malformed)?;
            let sorted = list.windows(2).all(|e| e[0] >> OBJECT_BITS <= e[1] >> OBJECT_BITS);
            if !sorted || list.iter().any(|&e| (e & OBJECT_MASK) as usize >= scene.object_count()) {
                return Err(Malformed);
            }
        }
        let n = 1u32 << buffer.level;
        for (light, cube) in words[Words::HEADER..buffer.cells].chunks_exact(Words::CUBE).map(Cube::read).enumerate() {
            if cube.light != scene.lights[light].position.wide() {
                return Err(OtherScene);
            }
            let rects_fit = cube.faces.iter().all(|&(first, rect)| {
                let [low, size] = [rect, rect >> 16].map(|w| [w & 0xFF, w >> 8 & 0xFF]);
                (0..2).all(|k| low[k] + size[k] <= n) && first + ((size[0] * size[1]) as usize) < starts.len()
            });
            if !rects_fit || cube.own >= starts.len() - 1 {
                return Err(Malformed);
            }
            for id in scene.object_ids() {
                let listed = |cell: Option<usize>, depth: u32| {
                    cell.and_then(list)
                        .is_some_and(|l| l.iter().any(|&e| e & OBJECT_MASK == id.0 && e >> OBJECT_BITS <= depth))
                };
                let seen = match footprint(scene.shape(id).bounds(), cube.light, MARGIN, buffer.level as u32) {
                    Footprint::Around => listed(Some(cube.own), 0),
                    Footprint::Faces(rects) => rects.iter().enumerate().all(|(face, rect)| {
                        rect.is_none_or(|r| {
                            (r.low[0]..=r.high[0]).all(|i| {
                                (r.low[1]..=r.high[1]).all(|j| listed(cube.cell(face, i as u32, j as u32), r.depth))
                            })
                        })
                    }),
                };
                if !seen {
                    return Err(Incomplete { light, object: id });
                }
            }
        }
        Ok(buffer)
    }
}
