//! The scene-format parser: text in, a normalised [`Scene`] out, or every
//! error with its line and column.
//!
//! It reads the text twice, allocating nothing (the text may live in flash):
//! 1. the *survey* gathers the surfaces and the world-space extent of objects,
//!    eye and lights, which fixes the [`Normalization`];
//! 2. the *build* reads every statement again, reports every error, and
//!    stores the objects in normalised space.
//!
//! After an error the parser skips to the next keyword and goes on, so one
//! run reports all errors. A scene with errors is cleared: nothing can be
//! rendered from it.
//!
//! No-panic contract: for any input text, [`parse`] returns (it neither
//! panics nor loops), in time linear in the text's length plus
//! O(objects · log surfaces).

mod error;
mod lexer;
mod number;
mod statement;

pub use error::{ErrorKind, Field, Found, ParseError, Pos, Rule};
pub use lexer::{Lexer, Token};
pub use number::{parse_integer, Decimal};
pub use statement::{keyword, Statement, KEYWORDS};

use crate::capacity::Capacities;
use crate::scene::{
    Camera, CameraError, CapacityError, Light, Normalization, Scene, SurfaceEntry, WorldPoint,
};
use crate::shapes::{AxisAlignedBox, Rectangle, Sphere, Superquadric, Triangle};
use statement::Cursor;

/// What the parse found besides the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Parsed<'a> {
    /// The IMAGEFILE name, if given.
    pub imagefile: Option<&'a str>,
}

/// Reads every statement of `text`, handing each (or its error) to `each`;
/// skips to the next keyword after an error.
fn for_each_statement<'a>(
    text: &'a str,
    mut each: impl FnMut(Pos, Result<Statement<'a>, ParseError<'a>>),
) {
    let mut cur = Cursor::new(text);
    loop {
        let token = match cur.next() {
            Ok(Some(t)) => t,
            Ok(None) => return,
            Err(e) => {
                each(e.pos, Err(e));
                continue;
            }
        };
        let result = match keyword(token.text).filter(|_| !token.quoted) {
            Some(kw) => statement::statement(&mut cur, kw, token.pos),
            None => Err(ParseError::new(token.pos, ErrorKind::UnknownKeyword(token.text))),
        };
        let failed = result.is_err();
        each(token.pos, result);
        if failed {
            // Recover: skip to the next keyword.
            loop {
                match cur.peek() {
                    Ok(Some(t)) if keyword(t.text).is_none() || t.quoted => {
                        let _ = cur.next();
                    }
                    Ok(_) => break,
                    Err(e) => each(e.pos, Err(e)),
                }
            }
        }
    }
}

/// Parses `bytes`, reporting invalid UTF-8 as an error at the first bad byte.
pub fn parse_bytes<'a, C: Capacities>(
    bytes: &'a [u8],
    scene: &mut Scene<C>,
    on_error: &mut dyn FnMut(ParseError<'a>),
) -> Result<Parsed<'a>, usize> {
    match core::str::from_utf8(bytes) {
        Ok(text) => parse(text, scene, on_error),
        Err(e) => {
            let good = &bytes[..e.valid_up_to()];
            let line = 1 + good.iter().filter(|&&b| b == b'\n').count() as u32;
            let line_start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            // The valid prefix is UTF-8: count its characters on this line.
            let column = 1 + core::str::from_utf8(&good[line_start..]).map_or(0, |s| s.chars().count()) as u32;
            scene.clear();
            on_error(ParseError::new(Pos { line, column }, ErrorKind::InvalidUtf8));
            Err(1)
        }
    }
}

/// World bounds of everything that matters for the normalisation.
struct Extent {
    min: WorldPoint,
    max: WorldPoint,
}

impl Extent {
    fn add(&mut self, lo: WorldPoint, hi: WorldPoint) {
        for a in 0..3 {
            self.min[a] = self.min[a].min(lo[a]);
            self.max[a] = self.max[a].max(hi[a]);
        }
    }
}

/// Parses `text` into `scene` (cleared first). Every error goes to
/// `on_error`; the result is the number of errors if there were any.
pub fn parse<'a, C: Capacities>(
    text: &'a str,
    scene: &mut Scene<C>,
    on_error: &mut dyn FnMut(ParseError<'a>),
) -> Result<Parsed<'a>, usize> {
    scene.clear();
    survey(text, scene);
    let mut build = Build {
        scene,
        parsed: Parsed::default(),
        first: [None; PARAMETERS.len()],
        errors: 0,
        reported_capacity: 0,
        on_error,
    };
    for_each_statement(text, |pos, result| match result {
        Ok(s) => build.apply(pos, s),
        Err(e) => build.report(e),
    });
    build.check_camera();
    let (errors, parsed) = (build.errors, build.parsed);
    if errors > 0 {
        scene.clear();
        return Err(errors);
    }
    Ok(parsed)
}

/// Pass 1: surfaces (sorted by number) and the normalisation.
fn survey<C: Capacities>(text: &str, scene: &mut Scene<C>) {
    let mut eye = None;
    let mut extent: Option<Extent> = None;
    let mut add = |lo: WorldPoint, hi: WorldPoint| match &mut extent {
        Some(e) => e.add(lo, hi),
        None => extent = Some(Extent { min: lo, max: hi }),
    };
    for_each_statement(text, |pos, result| match result {
        Ok(Statement::Viewpoint(p)) => {
            eye.get_or_insert(p);
        }
        Ok(Statement::Light { position, .. }) => add(position, position),
        Ok(Statement::Surface { number, surface }) => {
            // A full arena is reported by the build pass.
            let _ = scene.push_surface(SurfaceEntry {
                number,
                line: pos.line,
                column: pos.column,
                surface,
            });
        }
        Ok(s) => {
            if let Some((lo, hi)) = s.object_bounds() {
                add(lo, hi);
            }
        }
        Err(_) => {}
    });
    let eye = eye.unwrap_or(scene.settings.view.eye);
    add(eye, eye);
    scene.sort_surfaces();
    if let Some(e) = extent {
        scene.normalization = Normalization::fit(e.min, e.max);
    }
}

/// Scene parameters that may appear once, in [`Build::first`] order.
const PARAMETERS: [&str; 11] = [
    "VIEWPOINT",
    "ORIGIN",
    "UPVECTOR",
    "RASTER",
    "VIEWPORT",
    "RDEPTH",
    "IMAGEFILE",
    "BACKGROUND",
    "GAMMA",
    "ATTENUATION",
    "SAMPLES",
];

/// Pass 2 state.
struct Build<'s, 'a, 'e, C: Capacities> {
    scene: &'s mut Scene<C>,
    parsed: Parsed<'a>,
    /// Where each parameter was first given.
    first: [Option<Pos>; PARAMETERS.len()],
    errors: usize,
    /// Bit set of capacities already reported (one error each is enough).
    reported_capacity: u32,
    on_error: &'e mut dyn FnMut(ParseError<'a>),
}

impl<'a, C: Capacities> Build<'_, 'a, '_, C> {
    fn report(&mut self, e: ParseError<'a>) {
        self.errors += 1;
        (self.on_error)(e);
    }

    fn capacity(&mut self, pos: Pos, e: CapacityError) {
        let bit = match e.what {
            "objects" => 1,
            "spheres" => 2,
            "boxes" => 4,
            "superquadrics" => 8,
            "triangles" => 16,
            "rectangles" => 32,
            "surfaces" => 64,
            _ => 128,
        };
        if self.reported_capacity & bit == 0 {
            self.reported_capacity |= bit;
            self.report(ParseError::new(pos, ErrorKind::Capacity(e)));
        } else {
            self.errors += 1;
        }
    }

    /// Records a parameter; false (with an error) if it was given before.
    fn once(&mut self, keyword: &'static str, pos: Pos) -> bool {
        let i = PARAMETERS.iter().position(|&k| k == keyword).unwrap_or(0);
        if let Some(first) = self.first[i] {
            self.report(ParseError::new(
                pos,
                ErrorKind::Repeated {
                    keyword,
                    first_line: first.line,
                },
            ));
            return false;
        }
        self.first[i] = Some(pos);
        true
    }

    /// The surface index for an object, or an error.
    fn surface(&mut self, keyword: &'static str, number: u32, pos: Pos) -> Option<u16> {
        let found = self.scene.view().surface_index(number);
        if found.is_none() && self.reported_capacity & 64 == 0 {
            self.report(ParseError::new(pos, ErrorKind::UndefinedSurface { keyword, number }));
        }
        found
    }

    fn apply(&mut self, pos: Pos, s: Statement<'a>) {
        let norm = self.scene.normalization;
        let too_small = |keyword| ParseError::new(pos, ErrorKind::TooSmall { keyword });
        match s {
            Statement::Viewpoint(p) => {
                if self.once("VIEWPOINT", pos) {
                    self.scene.settings.view.eye = p;
                }
            }
            Statement::Origin(p) => {
                if self.once("ORIGIN", pos) {
                    self.scene.settings.view.look_at = p;
                }
            }
            Statement::Upvector(p) => {
                if self.once("UPVECTOR", pos) {
                    self.scene.settings.view.up = p;
                }
            }
            Statement::Raster(r) => {
                if self.once("RASTER", pos) {
                    self.scene.settings.raster = r;
                }
            }
            Statement::Viewport(v) => {
                if self.once("VIEWPORT", pos) {
                    self.scene.settings.view.viewport = Some(v);
                }
            }
            Statement::Rdepth(d) => {
                if self.once("RDEPTH", pos) {
                    self.scene.settings.rdepth = d;
                }
            }
            Statement::Imagefile(name) => {
                if self.once("IMAGEFILE", pos) {
                    self.parsed.imagefile = Some(name);
                }
            }
            Statement::Background(c) => {
                if self.once("BACKGROUND", pos) {
                    self.scene.settings.background = c;
                }
            }
            Statement::Gamma(g) => {
                if self.once("GAMMA", pos) {
                    self.scene.settings.gamma = g;
                }
            }
            Statement::Attenuation(d) => {
                if self.once("ATTENUATION", pos) {
                    self.scene.settings.attenuation = d;
                }
            }
            Statement::Samples(n) => {
                if self.once("SAMPLES", pos) {
                    self.scene.settings.samples = n;
                }
            }
            Statement::Light { brightness, position } => {
                let light = Light {
                    position: norm.point(position),
                    brightness,
                };
                if let Err(e) = self.scene.push_light(light) {
                    self.capacity(pos, e);
                }
            }
            Statement::Surface { number, .. } => {
                let view = self.scene.view();
                match view.surface_index(number).map(|i| view.surfaces[i as usize]) {
                    Some(first) if (first.line, first.column) != (pos.line, pos.column) => self.report(ParseError::new(
                        pos,
                        ErrorKind::SurfaceRepeated {
                            number,
                            first_line: first.line,
                        },
                    )),
                    Some(_) => {}
                    None => self.capacity(
                        pos,
                        CapacityError {
                            what: "surfaces",
                            capacity: Scene::<C>::surface_capacity(),
                            profile: C::NAME,
                        },
                    ),
                }
            }
            Statement::Sphere { surface, radius, center } => {
                let Some(surface) = self.surface("SPHERE", surface, pos) else { return };
                let radius = norm.length(radius);
                if radius.to_bits() <= 0 {
                    return self.report(too_small("SPHERE"));
                }
                let r = self.scene.push_sphere(Sphere::new(norm.point(center), radius, surface));
                if let Err(e) = r {
                    self.capacity(pos, e);
                }
            }
            Statement::Box { surface, center, half } => {
                let Some(surface) = self.surface("BOX", surface, pos) else { return };
                let min = norm.point([0, 1, 2].map(|a| center[a] - half[a]));
                let max = norm.point([0, 1, 2].map(|a| center[a] + half[a]));
                if (0..3).any(|a| min.axis(a) >= max.axis(a)) {
                    return self.report(too_small("BOX"));
                }
                let b = AxisAlignedBox { min, max, surface };
                if let Err(e) = self.scene.push_box(b) {
                    self.capacity(pos, e);
                }
            }
            Statement::Superquadric {
                surface,
                power,
                center,
                half,
            } => {
                let Some(surface) = self.surface("SUPERQUADRIC", surface, pos) else { return };
                let half = crate::math::Vec3 {
                    x: norm.length(half[0]),
                    y: norm.length(half[1]),
                    z: norm.length(half[2]),
                };
                if half.bits().iter().any(|&h| h <= 0) {
                    return self.report(too_small("SUPERQUADRIC"));
                }
                let power = crate::math::Scalar::from_bits(statement::q32_to_q16(power.to_bits()) as i32);
                let q = Superquadric::new(norm.point(center), half, power, surface);
                if let Err(e) = self.scene.push_superquadric(q) {
                    self.capacity(pos, e);
                }
            }
            Statement::Triangle { surface, corners } => {
                let Some(surface) = self.surface("TRIANGLE", surface, pos) else { return };
                let Some(t) = Triangle::new(corners.map(|c| norm.point(c)), surface) else {
                    return self.report(too_small("TRIANGLE"));
                };
                if let Err(e) = self.scene.push_triangle(t) {
                    self.capacity(pos, e);
                }
            }
            Statement::Rectangle { surface, corners } => {
                let Some(surface) = self.surface("RECTANGLE", surface, pos) else { return };
                let Some(r) = Rectangle::new(corners.map(|c| norm.point(c)), surface) else {
                    return self.report(too_small("RECTANGLE"));
                };
                if let Err(e) = self.scene.push_rectangle(r) {
                    self.capacity(pos, e);
                }
            }
        }
    }

    /// The camera needs VIEWPOINT ≠ ORIGIN and an UPVECTOR off the view line.
    fn check_camera(&mut self) {
        let at = |i: usize| self.first[i];
        let start = Pos { line: 1, column: 1 };
        let view_pos = at(0).max(at(1)).unwrap_or(start);
        match Camera::check(&self.scene.settings.view) {
            Ok(()) => {}
            Err(CameraError::EyeAtOrigin) => self.report(ParseError::new(view_pos, ErrorKind::EyeAtOrigin)),
            Err(CameraError::UpParallel) => {
                let pos = at(2).unwrap_or(view_pos);
                self.report(ParseError::new(pos, ErrorKind::UpParallel))
            }
        }
    }
}
