//! One statement of the scene format, read into world units (Q32.32) and
//! checked for everything that needs no other statement: syntax, ranges and
//! degenerate shapes.

use super::error::{ErrorKind, Field, Found, ParseError, Pos, Rule};
use super::keyword::Keyword;
use super::lexer::{Lexer, Token};
use super::number::{parse_integer, Decimal};
use crate::capacity::{Arena, CapacityKind, Counts};
use crate::math::isqrt_u128;
use crate::scene::SceneCapacities;
use crate::scene::{Color, Frames, Surface, WorldPoint, WorldValue, MAX_SAMPLES, MAX_SIDE};
use crate::shapes::bspline::{MAX_CONTROL_SIDE, MAX_ORDER, MAX_SAMPLE_SIDE};
use crate::shapes::{Rectangle, Triangle};
use core::marker::PhantomData;
use fixed::types::{I32F32, I48F16};

/// Which shapes' geometric checks a parse runs. A profile without room for
/// a kind makes each of its statements a capacity error anyway, so a board
/// that holds no rectangles (say) skips their checks and links none of that
/// code; the capacity error still names the first such statement.
pub(crate) trait Room {
    /// Rectangles are checked for area, planarity and convexity.
    const RECTANGLES: bool;
    /// Triangles are checked for area.
    const TRIANGLES: bool;
}

/// Every check: what [`count`](super::count) needs (it holds no scene).
pub(crate) struct AnyRoom;

impl Room for AnyRoom {
    const RECTANGLES: bool = true;
    const TRIANGLES: bool = true;
}

/// The checks for the shapes the profile `C` has room for.
pub(crate) struct RoomOf<C>(PhantomData<C>);

impl<C: SceneCapacities> Room for RoomOf<C> {
    const RECTANGLES: bool = <C::Rectangles as Arena<Rectangle>>::CAPACITY > 0;
    const TRIANGLES: bool = <C::Triangles as Arena<Triangle>>::CAPACITY > 0;
}

/// A statement's content, in world units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Statement<'a> {
    Viewpoint(WorldPoint),
    Origin(WorldPoint),
    Upvector(WorldPoint),
    Raster([u32; 2]),
    Viewport([WorldValue; 2]),
    Rdepth(u32),
    Imagefile(&'a str),
    Light { brightness: I32F32, position: WorldPoint },
    Background(Color),
    Gamma(I32F32),
    Attenuation(I32F32),
    Samples(u32),
    Sphere { surface: u32, radius: WorldValue, center: WorldPoint },
    Box { surface: u32, center: WorldPoint, half: WorldPoint },
    Superquadric { surface: u32, power: I32F32, center: WorldPoint, half: WorldPoint },
    Triangle { surface: u32, corners: [WorldPoint; 3] },
    Rectangle { surface: u32, corners: [WorldPoint; 4] },
    Bspline(Patch<'a>),
    Surface { number: u32, surface: Surface },
    Frames(Frames),
    Move(Keys<'a>),
}

/// A B-spline patch: its control points stay in the text (validated), read
/// again when needed, so the statement is small whatever their number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Patch<'a> {
    pub surface: u32,
    pub order: u32,
    pub rows: u32,
    pub cols: u32,
    /// Points evaluated along u and v.
    pub samples: [u32; 2],
    pub points: ControlPoints<'a>,
}

/// A patch's control points as they stand in the scene text, already
/// checked to be `count` valid points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ControlPoints<'a> {
    lexer: Lexer<'a>,
    count: u32,
}

impl<'a> ControlPoints<'a> {
    /// The points in world units, row by row.
    pub fn iter(&self) -> impl Iterator<Item = WorldPoint> + 'a {
        let mut lexer = self.lexer;
        let mut number = move || match lexer.next_token() {
            Ok(Some(t)) => Decimal::parse(t.text).map_or(0, |d| d.to_q32()),
            _ => 0,
        };
        (0..self.count).map(move |_| [number(), number(), number()])
    }
}

/// A MOVE's keys as they stand in the scene text, already checked to be
/// `count` keys (a frame, then a displacement), their frames strictly
/// increasing: read again when needed, like a patch's control points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Keys<'a> {
    lexer: Lexer<'a>,
    count: u32,
}

/// One key of a MOVE: at `frame`, the displacement `offset` (world units).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Key {
    pub frame: u32,
    /// Where the frame is written, for errors about it.
    pub pos: Pos,
    pub offset: WorldPoint,
}

impl<'a> Keys<'a> {
    /// The keys, in the order written (frames increasing).
    pub fn iter(&self) -> impl Iterator<Item = Key> + 'a {
        let mut lexer = self.lexer;
        let mut token = move || match lexer.next_token() {
            Ok(Some(t)) => (t.pos, Decimal::parse(t.text).map_or(0, |d| d.to_q32())),
            _ => (Pos { line: 1, column: 1 }, 0),
        };
        (0..self.count).map(move |_| {
            let (pos, frame) = token();
            let offset = [token().1, token().1, token().1];
            Key { frame: (frame >> 32) as u32, pos, offset }
        })
    }

    /// The keys as (frame, displacement) for [`crate::scene::displacement_at`].
    pub fn offsets(&self) -> impl Iterator<Item = (u32, WorldPoint)> + 'a {
        self.iter().map(|k| (k.frame, k.offset))
    }
}

impl Statement<'_> {
    /// The world-space box holding an object statement, if it is one.
    pub fn object_bounds(&self) -> Option<(WorldPoint, WorldPoint)> {
        let spread = |c: WorldPoint, h: WorldPoint| ([0, 1, 2].map(|a| c[a] - h[a]), [0, 1, 2].map(|a| c[a] + h[a]));
        let corners = |cs: &[WorldPoint]| {
            let mut lo = cs[0];
            let mut hi = cs[0];
            for c in cs {
                for a in 0..3 {
                    lo[a] = lo[a].min(c[a]);
                    hi[a] = hi[a].max(c[a]);
                }
            }
            (lo, hi)
        };
        match self {
            Statement::Sphere { radius, center, .. } => Some(spread(*center, [*radius; 3])),
            Statement::Box { center, half, .. } | Statement::Superquadric { center, half, .. } => {
                Some(spread(*center, *half))
            }
            Statement::Triangle { corners: c, .. } => Some(corners(c)),
            Statement::Rectangle { corners: c, .. } => Some(corners(c)),
            // The surface lies within its control points' convex hull.
            Statement::Bspline(Patch { points, .. }) => {
                let mut all = points.iter();
                let first = all.next()?;
                Some(all.fold((first, first), |(lo, hi), p| {
                    ([0, 1, 2].map(|a| lo[a].min(p[a])), [0, 1, 2].map(|a| hi[a].max(p[a])))
                }))
            }
            Statement::Viewpoint(_)
            | Statement::Origin(_)
            | Statement::Upvector(_)
            | Statement::Raster(_)
            | Statement::Viewport(_)
            | Statement::Rdepth(_)
            | Statement::Imagefile(_)
            | Statement::Light { .. }
            | Statement::Background(_)
            | Statement::Gamma(_)
            | Statement::Attenuation(_)
            | Statement::Samples(_)
            | Statement::Surface { .. }
            | Statement::Frames(_)
            | Statement::Move(_) => None,
        }
    }

    /// Adds what this statement stores to `counts` (a B-spline patch: its
    /// full grid of triangles, and its control points as scratch room).
    pub(crate) fn count(&self, counts: &mut Counts) {
        let kind = match self {
            Statement::Sphere { .. } => CapacityKind::Spheres,
            Statement::Box { .. } => CapacityKind::Boxes,
            Statement::Superquadric { .. } => CapacityKind::Superquadrics,
            Statement::Triangle { .. } => CapacityKind::Triangles,
            Statement::Rectangle { .. } => CapacityKind::Rectangles,
            Statement::Surface { .. } => CapacityKind::Surfaces,
            Statement::Light { .. } => CapacityKind::Lights,
            Statement::Bspline(Patch { samples, points, .. }) => {
                let cells =
                    (samples[0].saturating_sub(1) as usize).saturating_mul(samples[1].saturating_sub(1) as usize);
                counts.bspline_triangles = counts.bspline_triangles.saturating_add(cells.saturating_mul(2));
                counts.control_points = counts.control_points.max(points.iter().count());
                return;
            }
            Statement::Viewpoint(_)
            | Statement::Origin(_)
            | Statement::Upvector(_)
            | Statement::Raster(_)
            | Statement::Viewport(_)
            | Statement::Rdepth(_)
            | Statement::Imagefile(_)
            | Statement::Background(_)
            | Statement::Gamma(_)
            | Statement::Attenuation(_)
            | Statement::Samples(_)
            | Statement::Frames(_)
            | Statement::Move(_) => return,
        };
        let count = counts.get_mut(kind);
        *count = count.saturating_add(1);
    }

    /// The keyword that begins the statement.
    pub(crate) fn keyword(&self) -> Keyword {
        match self {
            Statement::Viewpoint(_) => Keyword::Viewpoint,
            Statement::Origin(_) => Keyword::Origin,
            Statement::Upvector(_) => Keyword::Upvector,
            Statement::Raster(_) => Keyword::Raster,
            Statement::Viewport(_) => Keyword::Viewport,
            Statement::Rdepth(_) => Keyword::Rdepth,
            Statement::Imagefile(_) => Keyword::Imagefile,
            Statement::Light { .. } => Keyword::Light,
            Statement::Background(_) => Keyword::Background,
            Statement::Gamma(_) => Keyword::Gamma,
            Statement::Attenuation(_) => Keyword::Attenuation,
            Statement::Samples(_) => Keyword::Samples,
            Statement::Sphere { .. } => Keyword::Sphere,
            Statement::Box { .. } => Keyword::Box,
            Statement::Superquadric { .. } => Keyword::Superquadric,
            Statement::Triangle { .. } => Keyword::Triangle,
            Statement::Rectangle { .. } => Keyword::Rectangle,
            Statement::Bspline(_) => Keyword::Bspline,
            Statement::Surface { .. } => Keyword::Surface,
            Statement::Frames(_) => Keyword::Frames,
            Statement::Move(_) => Keyword::Move,
        }
    }
}

/// Tokens with one token of look-ahead.
pub struct Cursor<'a> {
    lexer: Lexer<'a>,
    peeked: Option<Option<Token<'a>>>,
    /// Just after the last token taken: where "found the end of the file"
    /// points, inside the statement the end cuts short.
    taken_end: Pos,
}

impl<'a> Cursor<'a> {
    pub fn new(text: &'a str) -> Cursor<'a> {
        Cursor { lexer: Lexer::new(text), peeked: None, taken_end: Pos { line: 1, column: 1 } }
    }

    pub fn peek(&mut self) -> Result<Option<Token<'a>>, ParseError<'a>> {
        if let Some(t) = self.peeked {
            return Ok(t);
        }
        let t = self.lexer.next_token()?;
        self.peeked = Some(t);
        Ok(t)
    }

    pub fn next(&mut self) -> Result<Option<Token<'a>>, ParseError<'a>> {
        let t = self.peek()?;
        self.take();
        Ok(t)
    }

    /// Whether `token` (the one peeked) begins a line after the last token
    /// taken: where a statement may begin again after an error.
    pub fn on_a_later_line(&self, token: Token<'a>) -> bool {
        token.pos.line > self.taken_end.line
    }

    /// Consumes the peeked token.
    fn take(&mut self) {
        if let Some(Some(t)) = self.peeked.take() {
            self.taken_end = t.end;
        }
    }

    /// The error for a statement that the end of the text cuts short.
    fn end_of_file(&self, kind: ErrorKind<'a>) -> ParseError<'a> {
        ParseError::new(self.taken_end, kind)
    }

    /// The next token if it is a number, else the error for `field`. The
    /// token is not consumed: the caller consumes it once it is accepted,
    /// so error recovery always starts at the offending token.
    fn number(&mut self, field: Field) -> Result<(Decimal, Token<'a>), ParseError<'a>> {
        match self.peek()? {
            None => Err(self.end_of_file(ErrorKind::ExpectedNumber { field, found: Found::EndOfFile })),
            Some(t) => match Decimal::parse(t.text).filter(|_| !t.quoted) {
                None => Err(ParseError::new(t.pos, ErrorKind::ExpectedNumber { field, found: found(t) })),
                Some(d) if d.out_of_range() => Err(out_of_range(t, field, Rule::Magnitude)),
                Some(d) => Ok((d, t)),
            },
        }
    }

    /// A real number in Q32.32 satisfying `rule`.
    fn real(&mut self, field: Field, rule: Rule) -> Result<i64, ParseError<'a>> {
        let (d, t) = self.number(field)?;
        let v = d.to_q32();
        let ok = match rule {
            Rule::Positive => v > 0,
            Rule::NonNegative => v >= 0,
            Rule::UnitInterval => (0..=1 << 32).contains(&v),
            Rule::BetweenReal(lo, hi) => v >= lo << 32 && v <= hi << 32,
            Rule::Between(..) | Rule::Magnitude | Rule::AboveResolution => true,
        };
        if ok {
            self.take();
            Ok(v)
        } else if rule == Rule::Positive && !d.negative && !d.is_zero() {
            Err(out_of_range(t, field, Rule::AboveResolution))
        } else {
            Err(out_of_range(t, field, rule))
        }
    }

    /// Whether the next token is a number (more of a statement whose
    /// length varies: a rate, a key).
    /// The lexer's error there (an unterminated comment or string) is the
    /// statement's: dropped, it would end the text without a word.
    #[inline(never)]
    fn number_follows(&mut self) -> Result<bool, ParseError<'a>> {
        Ok(matches!(self.peek()?, Some(t) if !t.quoted && Decimal::parse(t.text).is_some()))
    }

    /// An integer from `lo` to `hi`.
    fn integer(&mut self, field: Field, lo: i64, hi: i64) -> Result<i64, ParseError<'a>> {
        let t = match self.peek()? {
            None => return Err(self.end_of_file(ErrorKind::ExpectedInteger { field, found: Found::EndOfFile })),
            Some(t) => t,
        };
        let v = parse_integer(t.text)
            .filter(|_| !t.quoted)
            .ok_or(ParseError::new(t.pos, ErrorKind::ExpectedInteger { field, found: found(t) }))?;
        if v < lo || v > hi {
            return Err(out_of_range(t, field, Rule::Between(lo, hi)));
        }
        self.take();
        Ok(v)
    }

    fn point(&mut self, keyword: Keyword, names: [&'static str; 3]) -> Result<WorldPoint, ParseError<'a>> {
        let mut p = [0; 3];
        for (v, name) in p.iter_mut().zip(names) {
            *v = self.real(Field { statement: keyword.name(), name }, Rule::Magnitude)?;
        }
        Ok(p)
    }

    fn positive_triple(&mut self, keyword: Keyword, names: [&'static str; 3]) -> Result<WorldPoint, ParseError<'a>> {
        let mut p = [0; 3];
        for (v, name) in p.iter_mut().zip(names) {
            *v = self.real(Field { statement: keyword.name(), name }, Rule::Positive)?;
        }
        Ok(p)
    }

    fn color(&mut self, keyword: Keyword, names: [&'static str; 3]) -> Result<Color, ParseError<'a>> {
        let mut c = [0; 3];
        for (v, name) in c.iter_mut().zip(names) {
            *v = q32_to_q16(self.real(Field { statement: keyword.name(), name }, Rule::UnitInterval)?) as i32;
        }
        Ok(Color::from_bits(c))
    }

    fn surface_number(&mut self, keyword: Keyword) -> Result<u32, ParseError<'a>> {
        let field = Field { statement: keyword.name(), name: "surface number" };
        Ok(self.integer(field, 0, super::number::LIMIT as i64)? as u32)
    }
}

/// What `t` is, as an error shows it: a quoted string says so.
fn found(t: Token<'_>) -> Found<'_> {
    match t.quoted {
        true => Found::Quoted(t.text),
        false => Found::Token(t.text),
    }
}

fn out_of_range<'a>(t: Token<'a>, field: Field, rule: Rule) -> ParseError<'a> {
    ParseError::new(t.pos, ErrorKind::OutOfRange { field, rule, found: t.text })
}

/// Q32.32 to Q16.16, rounded to nearest.
pub fn q32_to_q16(v: i64) -> i64 {
    (v + (1 << 15)) >> 16
}

/// Reads the statement that `keyword` (already consumed) begins.
/// The shapes' geometric checks run only where `R` has room for them.
pub fn statement<'a, R: Room>(cur: &mut Cursor<'a>, kw: Keyword, at: Pos) -> Result<Statement<'a>, ParseError<'a>> {
    let f = |name| Field { statement: kw.name(), name };
    let xyz = ["x", "y", "z"];
    Ok(match kw {
        Keyword::Viewpoint => Statement::Viewpoint(cur.point(kw, xyz)?),
        Keyword::Origin => Statement::Origin(cur.point(kw, xyz)?),
        Keyword::Upvector => Statement::Upvector(cur.point(kw, xyz)?),
        Keyword::Raster => Statement::Raster([
            cur.integer(f("width"), 1, MAX_SIDE as i64)? as u32,
            cur.integer(f("height"), 1, MAX_SIDE as i64)? as u32,
        ]),
        Keyword::Viewport => {
            Statement::Viewport([cur.real(f("width"), Rule::Positive)?, cur.real(f("height"), Rule::Positive)?])
        }
        Keyword::Rdepth => Statement::Rdepth(cur.integer(f("depth"), 0, super::number::LIMIT as i64)? as u32),
        Keyword::Imagefile => match cur.next()? {
            Some(t) => Statement::Imagefile(t.text),
            None => return Err(cur.end_of_file(ErrorKind::ExpectedName { field: f("file name") })),
        },
        Keyword::Light => Statement::Light {
            brightness: I32F32::from_bits(cur.real(f("brightness"), Rule::NonNegative)?),
            position: cur.point(kw, xyz)?,
        },
        Keyword::Background => Statement::Background(cur.color(kw, ["red", "green", "blue"])?),
        Keyword::Gamma => Statement::Gamma(I32F32::from_bits(cur.real(f("value"), Rule::Positive)?)),
        Keyword::Attenuation => Statement::Attenuation(I32F32::from_bits(cur.real(f("d0"), Rule::Positive)?)),
        Keyword::Samples => Statement::Samples(cur.integer(f("count"), 1, MAX_SAMPLES as i64)? as u32),
        Keyword::Sphere => Statement::Sphere {
            surface: cur.surface_number(kw)?,
            radius: cur.real(f("radius"), Rule::Positive)?,
            center: cur.point(kw, xyz)?,
        },
        Keyword::Box => Statement::Box {
            surface: cur.surface_number(kw)?,
            center: cur.point(kw, ["xc", "yc", "zc"])?,
            half: cur.positive_triple(kw, ["xs", "ys", "zs"])?,
        },
        Keyword::Superquadric => Statement::Superquadric {
            surface: cur.surface_number(kw)?,
            power: I32F32::from_bits(cur.real(f("power"), Rule::BetweenReal(2, 64))?),
            center: cur.point(kw, ["xc", "yc", "zc"])?,
            half: cur.positive_triple(kw, ["xs", "ys", "zs"])?,
        },
        Keyword::Triangle => {
            let surface = cur.surface_number(kw)?;
            let corners = [
                cur.point(kw, ["x1", "y1", "z1"])?,
                cur.point(kw, ["x2", "y2", "z2"])?,
                cur.point(kw, ["x3", "y3", "z3"])?,
            ];
            if R::TRIANGLES && cross(sub(corners[1], corners[0]), sub(corners[2], corners[0])) == [0; 3] {
                return Err(ParseError::new(
                    at,
                    ErrorKind::Degenerate { keyword: kw.name(), why: "its corners are collinear (zero area)" },
                ));
            }
            Statement::Triangle { surface, corners }
        }
        Keyword::Rectangle => {
            let surface = cur.surface_number(kw)?;
            let corners = [
                cur.point(kw, ["x1", "y1", "z1"])?,
                cur.point(kw, ["x2", "y2", "z2"])?,
                cur.point(kw, ["x3", "y3", "z3"])?,
                cur.point(kw, ["x4", "y4", "z4"])?,
            ];
            if R::RECTANGLES {
                check_quadrilateral(&corners).map_err(|k| ParseError::new(at, k))?;
            }
            Statement::Rectangle { surface, corners }
        }
        Keyword::Bspline => {
            let surface = cur.surface_number(kw)?;
            let order = cur.integer(f("order"), 2, MAX_ORDER as i64)? as u32;
            let rows = cur.integer(f("rows"), 2, MAX_CONTROL_SIDE as i64)? as u32;
            let cols = cur.integer(f("cols"), 2, MAX_CONTROL_SIDE as i64)? as u32;
            let samples = [
                cur.integer(f("su"), 2, MAX_SAMPLE_SIDE as i64)? as u32,
                cur.integer(f("sv"), 2, MAX_SAMPLE_SIDE as i64)? as u32,
            ];
            if rows < order || cols < order {
                return Err(ParseError::new(at, ErrorKind::TooFewControlPoints { order, rows, cols }));
            }
            // Nothing is peeked after a number is taken: the lexer stands at
            // the first control point.
            let points = ControlPoints { lexer: cur.lexer, count: rows * cols };
            for _ in 0..rows * cols {
                cur.point(kw, ["control point x", "control point y", "control point z"])?;
            }
            Statement::Bspline(Patch { surface, order, rows, cols, samples, points })
        }
        Keyword::Surface => {
            let number = cur.surface_number(kw)?;
            let ambient = cur.color(kw, ["ambient red", "ambient green", "ambient blue"])?;
            let diffuse = cur.color(kw, ["diffuse red", "diffuse green", "diffuse blue"])?;
            let specular = cur.color(kw, ["specular red", "specular green", "specular blue"])?;
            let exponent = I48F16::from_bits(q32_to_q16(cur.real(f("specular exponent"), Rule::NonNegative)?));
            let reflectivity = q32_to_q16(cur.real(f("reflectivity"), Rule::UnitInterval)?) as i32;
            let transparency = q32_to_q16(cur.real(f("transparency"), Rule::UnitInterval)?) as i32;
            Statement::Surface {
                number,
                surface: Surface {
                    ambient,
                    diffuse,
                    specular,
                    exponent,
                    reflectivity: fixed::types::I16F16::from_bits(reflectivity),
                    transparency: fixed::types::I16F16::from_bits(transparency),
                },
            }
        }
        Keyword::Frames => {
            let count = cur.integer(f("count"), 1, Frames::MAX_COUNT as i64)? as u32;
            let rate = match cur.number_follows()? {
                true => cur.integer(f("rate"), 1, Frames::MAX_RATE as i64)? as u32,
                false => Frames::DEFAULT_RATE,
            };
            Statement::Frames(Frames { count, rate })
        }
        Keyword::Move => {
            // Nothing is peeked after the keyword: the lexer stands at the
            // first key.
            let mut keys = Keys { lexer: cur.lexer, count: 0 };
            let mut previous = None;
            loop {
                let at = cur.peek()?.map_or(cur.taken_end, |t| t.pos);
                let frame = cur.integer(f("frame"), 0, Frames::MAX_COUNT as i64 - 1)? as u32;
                if let Some(previous) = previous.filter(|&p| frame <= p) {
                    return Err(ParseError::new(at, ErrorKind::FramesOutOfOrder { frame, previous }));
                }
                cur.point(kw, ["dx", "dy", "dz"])?;
                keys.count += 1;
                previous = Some(frame);
                if !cur.number_follows()? {
                    break;
                }
            }
            Statement::Move(keys)
        }
    })
}

/// Whether `points` all lie on one line (or are one point), exactly.
pub(super) fn collinear(mut points: impl Iterator<Item = WorldPoint>) -> bool {
    let Some(first) = points.next() else { return true };
    let mut direction = None;
    for p in points {
        let along = sub(p, first);
        match direction {
            None if along != [0; 3] => direction = Some(along),
            Some(d) if cross(d, along) != [0; 3] => return false,
            _ => {}
        }
    }
    true
}

fn sub(a: WorldPoint, b: WorldPoint) -> [i128; 3] {
    [0, 1, 2].map(|i| a[i] as i128 - b[i] as i128)
}

fn cross(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: [i128; 3], b: [i128; 3]) -> i128 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Whether the edges `v` go round a rectangle along two axes: each along
/// one axis, the first and third along one, back and forth, the second and
/// fourth along the other. The tests below pass for such edges: all four
/// turns point along the third axis, one way, and the fourth corner lies in
/// the plane of the others. Saying so from signs spares a board their
/// 128-bit products (fig5_5's 64 tiles cost a Pico 7 M cycles).
fn goes_round_along_axes(v: &[[i128; 3]; 4]) -> bool {
    let axis = |edge: &[i128; 3]| {
        let mut along = (0..3).filter(|&a| edge[a] != 0);
        along.next().filter(|_| along.next().is_none())
    };
    let [Some(a0), Some(a1), Some(a2), Some(a3)] = [0, 1, 2, 3].map(|i| axis(&v[i])) else {
        return false;
    };
    a0 == a2 && a1 == a3 && a0 != a1 && (v[0][a0] > 0) != (v[2][a0] > 0) && (v[1][a1] > 0) != (v[3][a1] > 0)
}

/// A rectangle must have area, be planar (its fourth corner within 2^-10 of
/// its size from the plane of the others) and be strictly convex. Not
/// inlined: one copy for every parse of statements (the scene's, and the
/// count of its motion), a board's largest check.
#[inline(never)]
fn check_quadrilateral(c: &[WorldPoint; 4]) -> Result<(), ErrorKind<'static>> {
    // Work on edge vectors reduced to 24 significant bits: exact enough for
    // tolerance checks, and every product below fits an i128.
    let mut v = [[0i128; 3]; 4];
    for (i, e) in v.iter_mut().enumerate() {
        *e = sub(c[(i + 1) % 4], c[i]);
    }
    let largest = v.iter().flatten().map(|x| x.unsigned_abs()).max().unwrap_or(0);
    if largest == 0 {
        return Err(ErrorKind::Degenerate { keyword: Keyword::Rectangle.name(), why: "its corners coincide" });
    }
    // Each edge at its own scale for the turns: a short side of a long thin
    // rectangle, cut to nothing at the longest edge's scale, still turns
    // the way it does (a positive factor an edge keeps each turn's way).
    let own = v.map(|e| reduced(e, e.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0)));
    let v = v.map(|e| reduced(e, largest));
    if goes_round_along_axes(&v) {
        return Ok(());
    }
    check_reduced_edges(&v, &own)
}

/// `e` cut to 24 significant bits of `largest`. Not inlined: 128-bit steps
/// are long code on a 32-bit core.
#[inline(never)]
fn reduced(e: [i128; 3], largest: u128) -> [i128; 3] {
    let shift = (128 - largest.leading_zeros()).saturating_sub(24);
    e.map(|x| x >> shift)
}

/// The cross product of two vectors of components below 2^26 in
/// magnitude (sums of two `reduced` edges at most), its products made in 64
/// bits: 128-bit products are long code on a 32-bit core.
#[inline(never)]
fn cross_reduced(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    let (a, b) = (a.map(|x| x as i64), b.map(|x| x as i64));
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]].map(i128::from)
}

/// The turn at each corner of the quadrilateral of `reduced` edges.
fn corner_turns(v: &[[i128; 3]; 4]) -> [[i128; 3]; 4] {
    core::array::from_fn(|i| cross_reduced(v[i], v[(i + 1) % 4]))
}

/// [`check_quadrilateral`]'s tests on its edges reduced to 24 bits: `v` at
/// the longest edge's scale, `own` each at its own.
fn check_reduced_edges(v: &[[i128; 3]; 4], own: &[[i128; 3]; 4]) -> Result<(), ErrorKind<'static>> {
    // The turn at each corner; for a strictly convex quadrilateral all four
    // point the same way (counter-clockwise: along the front normal).
    if corner_turns(v) == [[0; 3]; 4] {
        return Err(ErrorKind::Degenerate {
            keyword: Keyword::Rectangle.name(),
            why: "its corners are collinear (zero area)",
        });
    }
    let turns = corner_turns(own);
    let reference = turns.iter().copied().max_by_key(|c| dot(*c, *c)).unwrap_or([0; 3]);
    if turns.iter().any(|c| dot(*c, reference) <= 0) {
        return Err(ErrorKind::NotConvex);
    }
    // Distance of p4 from the plane through p1 with the diagonals' normal n,
    // against the longest edge L: |(p4 − p1)·n| / |n| ≤ 2^-10 · L.
    let d1 = [0, 1, 2].map(|a| v[0][a] + v[1][a]); // p3 − p1
    let d2 = [0, 1, 2].map(|a| v[1][a] + v[2][a]); // p4 − p2
    let n = cross_reduced(d1, d2);
    let to4 = [0, 1, 2].map(|a| -v[3][a]); // p4 − p1 = −(p1 − p4)
    let off = dot(to4, n).unsigned_abs();
    // A corner exactly in the plane (every rectangle along the axes) needs
    // no square roots, which are long on a 32-bit core (fig5_5's 64 tiles
    // took 15 M cycles on a Pico).
    if off == 0 {
        return Ok(());
    }
    let longest = isqrt_u128(v.iter().map(|e| dot(*e, *e) as u128).max().unwrap_or(0));
    if off << 10 > longest * isqrt_u128(dot(n, n) as u128) {
        return Err(ErrorKind::NotPlanar);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::seeded;

    #[test]
    fn edges_round_along_axes_pass_every_test() {
        // Corners on a small grid, one coordinate mostly shared: many go
        // round along the axes, many nearly do (a corner off, a side
        // doubled back, an edge of length 0).
        let mut next = seeded(0x5eed_a1f9_0b3c_7d21);
        let mut small = || (next() % 5) as i128 - 2;
        let mut along = 0;
        for _ in 0..200_000 {
            let flat = (small() + 2) as usize % 3;
            let corners: [[i128; 3]; 4] = core::array::from_fn(|_| {
                let mut c = [small(), small(), small()];
                c[flat] = 0;
                c
            });
            let v: [[i128; 3]; 4] =
                core::array::from_fn(|i| [0, 1, 2].map(|a| corners[(i + 1) % 4][a] - corners[i][a]));
            if goes_round_along_axes(&v) {
                along += 1;
                assert_eq!(check_reduced_edges(&v, &v), Ok(()), "{corners:?}");
            }
        }
        assert!(along > 100, "{along} cases along the axes");
    }
}
