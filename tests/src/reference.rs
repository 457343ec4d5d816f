//! An independent double-precision (f64) reference ray tracer.
//!
//! It is written from the scene-format contract (`docs/scene-format.md`) alone and
//! shares no code with `octrace-core`: the accuracy test renders every scene
//! with both tracers and compares the images. The code aims to be obviously
//! correct rather than fast (O(objects) per ray, no acceleration structure).
//!
//! Rendering model, in short:
//! - camera rays from VIEWPOINT through the VIEWPORT (centred on ORIGIN);
//! - nearest hit with t > 0, ties go to the object earlier in the file;
//! - local colour = ambient + Σ lights B/(d + d0)·(diffuse·N·L + specular·(R·V)^k),
//!   with hard shadows cast by every object (transparent ones too);
//! - C = (1 − t)·C_local + t·C_behind + r·C_reflected, recursion while
//!   depth < RDEPTH; the transmitted ray continues unbent;
//! - each sample is clamped to [0, 1], samples are averaged, then gamma
//!   corrected and rounded (half up) to 0…255.
//!
//! - `BSPLINE` patches are evaluated here independently (Cox–de Boor in f64)
//!   into triangles carrying the surface normals at their corners; a hit on
//!   one is shaded with the barycentric blend of those normals, and its
//!   shadow rays leave from the hit point lifted onto the corners' tangent
//!   planes (when that lifts it towards the viewer's side), as the core does
//!   against shadow-terminator speckles.

use std::collections::BTreeMap;
use std::ops::{Add, Mul, Neg, Sub};

// ---------------------------------------------------------------------------
// Vectors
// ---------------------------------------------------------------------------

/// A 3-vector of f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl V3 {
    pub const fn new(x: f64, y: f64, z: f64) -> V3 {
        V3 { x, y, z }
    }
    fn dot(self, o: V3) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    fn cross(self, o: V3) -> V3 {
        V3::new(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)
    }
    fn length(self) -> f64 {
        self.dot(self).sqrt()
    }
    fn normalised(self) -> V3 {
        self * (1.0 / self.length())
    }
    fn get(self, i: usize) -> f64 {
        match i {
            0 => self.x,
            1 => self.y,
            _ => self.z,
        }
    }
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> V3 {
        V3::new(f(0), f(1), f(2))
    }
}

impl Add for V3 {
    type Output = V3;
    fn add(self, o: V3) -> V3 {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl Sub for V3 {
    type Output = V3;
    fn sub(self, o: V3) -> V3 {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Mul<f64> for V3 {
    type Output = V3;
    fn mul(self, s: f64) -> V3 {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl Neg for V3 {
    type Output = V3;
    fn neg(self) -> V3 {
        V3::new(-self.x, -self.y, -self.z)
    }
}

/// A linear RGB colour.
type Rgb = [f64; 3];

fn rgb_add(a: Rgb, b: Rgb) -> Rgb {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn rgb_scale(a: Rgb, s: f64) -> Rgb {
    [a[0] * s, a[1] * s, a[2] * s]
}

// ---------------------------------------------------------------------------
// Scene description
// ---------------------------------------------------------------------------

/// A material (`SURFACE` statement).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    pub ambient: Rgb,
    pub diffuse: Rgb,
    pub specular: Rgb,
    /// Specular exponent k (k = 0: the specular factor is 1).
    pub exponent: f64,
    pub reflectivity: f64,
    pub transparency: f64,
}

/// A white point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub brightness: f64,
    pub position: V3,
}

/// The geometry of one object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Sphere {
        centre: V3,
        radius: f64,
    },
    /// Axis-aligned box; `half` holds the half-sizes.
    Box {
        centre: V3,
        half: V3,
    },
    /// Σ |(x_i − c_i)/s_i|^power = 1.
    Superquadric {
        power: f64,
        centre: V3,
        half: V3,
    },
    /// Corners p1, p2, p3; `normal` = normalise((p2 − p1) × (p3 − p1)).
    Triangle {
        p: [V3; 3],
        normal: V3,
    },
    /// Planar convex quad, corners counter-clockwise seen from the front.
    Rectangle {
        p: [V3; 4],
        normal: V3,
    },
    /// A triangle of a B-spline patch, with the surface normals at its
    /// corners (turned to the front `normal`'s side).
    SmoothTriangle {
        p: [V3; 3],
        normal: V3,
        normals: [V3; 3],
    },
}

impl Shape {
    fn is_flat(&self) -> bool {
        matches!(self, Shape::Triangle { .. } | Shape::Rectangle { .. } | Shape::SmoothTriangle { .. })
    }
}

/// One object: a shape and the index of its surface in [`RefScene::surfaces`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Object {
    pub shape: Shape,
    pub surface: usize,
}

/// A parsed scene in world units (f64).
#[derive(Clone, Debug, PartialEq)]
pub struct RefScene {
    pub viewpoint: V3,
    pub origin: V3,
    pub upvector: V3,
    pub raster: (u32, u32),
    /// Explicit VIEWPORT (width, height), or `None` for the default.
    pub viewport: Option<(f64, f64)>,
    pub rdepth: u32,
    pub imagefile: Option<String>,
    pub lights: Vec<Light>,
    pub background: Rgb,
    pub gamma: f64,
    pub attenuation: f64,
    pub samples: u32,
    /// Objects in file order (the order matters for ties).
    pub objects: Vec<Object>,
    /// Surfaces, indexed by `Object::surface`.
    pub surfaces: Vec<Surface>,
}

// ---------------------------------------------------------------------------
// Parsing
// ---------------------------------------------------------------------------

struct Token {
    text: String,
    line: usize,
    col: usize,
}

fn tokenize(text: &str) -> Result<Vec<Token>, String> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let (mut i, mut line, mut col) = (0usize, 1usize, 1usize);
    // Advance one character, keeping line and column up to date.
    let step = |i: &mut usize, line: &mut usize, col: &mut usize| {
        if chars[*i] == '\n' {
            *line += 1;
            *col = 1;
        } else {
            *col += 1;
        }
        *i += 1;
    };
    let comment_start = |i: usize| -> Option<char> {
        if chars[i] == '/' && i + 1 < chars.len() && (chars[i + 1] == '*' || chars[i + 1] == '/') {
            Some(chars[i + 1])
        } else {
            None
        }
    };
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            step(&mut i, &mut line, &mut col);
        } else if comment_start(i) == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                step(&mut i, &mut line, &mut col);
            }
        } else if comment_start(i) == Some('*') {
            let (open_line, open_col) = (line, col);
            step(&mut i, &mut line, &mut col);
            step(&mut i, &mut line, &mut col);
            loop {
                if i >= chars.len() {
                    return Err(format!("{open_line}:{open_col}: unterminated comment opened on line {open_line}"));
                }
                if chars[i] == '*' && i + 1 < chars.len() && chars[i + 1] == '/' {
                    step(&mut i, &mut line, &mut col);
                    step(&mut i, &mut line, &mut col);
                    break;
                }
                step(&mut i, &mut line, &mut col);
            }
        } else if c == '"' {
            let (tl, tc) = (line, col);
            step(&mut i, &mut line, &mut col);
            let mut s = String::new();
            loop {
                if i >= chars.len() {
                    return Err(format!("{tl}:{tc}: unterminated quoted string"));
                }
                if chars[i] == '"' {
                    step(&mut i, &mut line, &mut col);
                    break;
                }
                s.push(chars[i]);
                step(&mut i, &mut line, &mut col);
            }
            tokens.push(Token { text: s, line: tl, col: tc });
        } else {
            let (tl, tc) = (line, col);
            let mut s = String::new();
            while i < chars.len() && !chars[i].is_whitespace() && comment_start(i).is_none() {
                s.push(chars[i]);
                step(&mut i, &mut line, &mut col);
            }
            tokens.push(Token { text: s, line: tl, col: tc });
        }
    }
    Ok(tokens)
}

/// True when `s` is `[+-]? digits? (. digits?)? ([eE] [+-]? digits)?` with at
/// least one mantissa digit.
fn is_number(s: &str) -> bool {
    let b = s.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let mut mantissa_digits = 0;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
        mantissa_digits += 1;
    }
    if i < b.len() && b[i] == b'.' {
        i += 1;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
            mantissa_digits += 1;
        }
    }
    if mantissa_digits == 0 {
        return false;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
            i += 1;
        }
        let mut exp_digits = 0;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
            exp_digits += 1;
        }
        if exp_digits == 0 {
            return false;
        }
    }
    i == b.len()
}

fn is_integer(s: &str) -> bool {
    let digits = s.strip_prefix(['+', '-']).unwrap_or(s);
    !digits.is_empty() && digits.bytes().all(|c| c.is_ascii_digit())
}

struct Parser {
    tokens: Vec<Token>,
    pos: usize,
    /// Position reported for "unexpected end of file".
    end: (usize, usize),
}

impl Parser {
    fn next(&mut self, what: &str) -> Result<&Token, String> {
        match self.tokens.get(self.pos) {
            Some(t) => {
                self.pos += 1;
                Ok(t)
            }
            None => Err(format!("{}:{}: expected {what}, found end of file", self.end.0, self.end.1)),
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, String> {
        let t = self.next(what)?;
        let v = if is_number(&t.text) { t.text.parse::<f64>().ok() } else { None };
        match v {
            Some(v) if v.abs() <= 1e6 => Ok(v),
            Some(v) => Err(format!("{}:{}: {what} is out of range (magnitude above 1e6), found {v}", t.line, t.col)),
            None => Err(format!("{}:{}: expected {what} (a number), found `{}`", t.line, t.col, t.text)),
        }
    }

    fn integer(&mut self, what: &str, min: i64, max: i64) -> Result<i64, String> {
        let t = self.next(what)?;
        let v = if is_integer(&t.text) { t.text.parse::<i64>().ok() } else { None };
        match v {
            Some(v) if (min..=max).contains(&v) => Ok(v),
            Some(v) => Err(format!("{}:{}: {what} must be in {min}..={max}, found {v}", t.line, t.col)),
            None => Err(format!("{}:{}: expected {what} (an integer), found `{}`", t.line, t.col, t.text)),
        }
    }

    /// A number that must satisfy `ok`; `rule` describes the requirement.
    fn checked(&mut self, what: &str, rule: &str, ok: impl Fn(f64) -> bool) -> Result<f64, String> {
        let (line, col) = self.tokens.get(self.pos).map_or(self.end, |t| (t.line, t.col));
        let v = self.number(what)?;
        if ok(v) {
            Ok(v)
        } else {
            Err(format!("{line}:{col}: {what} must be {rule}, found {v}"))
        }
    }

    fn vec3(&mut self, what: &str) -> Result<V3, String> {
        Ok(V3::new(self.number(what)?, self.number(what)?, self.number(what)?))
    }

    fn colour(&mut self, what: &str) -> Result<Rgb, String> {
        Ok([self.number(what)?, self.number(what)?, self.number(what)?])
    }
}

/// Parse a scene. Errors are `line:col: message`.
pub fn parse(text: &str) -> Result<RefScene, String> {
    let tokens = tokenize(text)?;
    let end = {
        let lines = text.split('\n').count().max(1);
        let last_col = text.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (lines, last_col)
    };
    let mut p = Parser { tokens, pos: 0, end };

    let mut scene = RefScene {
        viewpoint: V3::new(0.0, 0.0, 10.0),
        origin: V3::new(0.0, 0.0, 0.0),
        upvector: V3::new(0.0, 1.0, 0.0),
        raster: (320, 240),
        viewport: None,
        rdepth: 3,
        imagefile: None,
        lights: Vec::new(),
        background: [0.0; 3],
        gamma: 2.2,
        attenuation: 1.0,
        samples: 1,
        objects: Vec::new(),
        surfaces: Vec::new(),
    };
    // Scene parameters seen so far, with the line they were given on.
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    // Surface number -> index in scene.surfaces.
    let mut surface_index: BTreeMap<i64, usize> = BTreeMap::new();
    // For each object: the surface number it refers to and where.
    let mut references: Vec<(i64, usize, usize)> = Vec::new();

    while p.pos < p.tokens.len() {
        let (line, col) = (p.tokens[p.pos].line, p.tokens[p.pos].col);
        let keyword = p.tokens[p.pos].text.to_ascii_uppercase();
        p.pos += 1;
        let is_parameter = matches!(
            keyword.as_str(),
            "VIEWPOINT"
                | "ORIGIN"
                | "UPVECTOR"
                | "RASTER"
                | "VIEWPORT"
                | "RDEPTH"
                | "IMAGEFILE"
                | "BACKGROUND"
                | "GAMMA"
                | "ATTENUATION"
                | "SAMPLES"
        );
        if is_parameter {
            if let Some(first) = seen.insert(keyword.clone(), line) {
                return Err(format!("{line}:{col}: {keyword} given twice (lines {first} and {line})"));
            }
        }
        match keyword.as_str() {
            "VIEWPOINT" => scene.viewpoint = p.vec3("VIEWPOINT coordinate")?,
            "ORIGIN" => scene.origin = p.vec3("ORIGIN coordinate")?,
            "UPVECTOR" => scene.upvector = p.vec3("UPVECTOR component")?,
            "RASTER" => {
                let w = p.integer("RASTER width", 1, 16384)?;
                let h = p.integer("RASTER height", 1, 16384)?;
                scene.raster = (w as u32, h as u32);
            }
            "VIEWPORT" => {
                let w = p.checked("VIEWPORT width", "> 0", |v| v > 0.0)?;
                let h = p.checked("VIEWPORT height", "> 0", |v| v > 0.0)?;
                scene.viewport = Some((w, h));
            }
            "RDEPTH" => scene.rdepth = p.integer("RDEPTH", 0, 1_000_000)? as u32,
            "IMAGEFILE" => scene.imagefile = Some(p.next("a file name")?.text.clone()),
            "LIGHT" => {
                let brightness = p.checked("LIGHT brightness", ">= 0", |v| v >= 0.0)?;
                let position = p.vec3("LIGHT coordinate")?;
                scene.lights.push(Light { brightness, position });
            }
            "BACKGROUND" => scene.background = p.colour("BACKGROUND component")?,
            "GAMMA" => scene.gamma = p.checked("GAMMA", "> 0", |v| v > 0.0)?,
            "ATTENUATION" => scene.attenuation = p.checked("ATTENUATION", "> 0", |v| v > 0.0)?,
            "SAMPLES" => scene.samples = p.integer("SAMPLES", 1, 16)? as u32,
            "SURFACE" => {
                let n = p.integer("surface number", 0, 1_000_000)?;
                let surface = Surface {
                    ambient: p.colour("ambient colour")?,
                    diffuse: p.colour("diffuse colour")?,
                    specular: p.colour("specular colour")?,
                    exponent: p.checked("specular exponent", ">= 0", |v| v >= 0.0)?,
                    reflectivity: p.number("reflectivity")?,
                    transparency: p.number("transparency")?,
                };
                if surface_index.insert(n, scene.surfaces.len()).is_some() {
                    return Err(format!("{line}:{col}: SURFACE {n} defined twice"));
                }
                scene.surfaces.push(surface);
            }
            "SPHERE" | "BOX" | "SUPERQUADRIC" | "TRIANGLE" | "RECTANGLE" => {
                let s = p.integer("surface number", 0, 1_000_000)?;
                let shape = parse_shape(&mut p, &keyword, line, col)?;
                references.push((s, line, col));
                scene.objects.push(Object { shape, surface: 0 });
            }
            "BSPLINE" => {
                let s = p.integer("surface number", 0, 1_000_000)?;
                let order = p.integer("BSPLINE order", 2, 8)? as usize;
                let rows = p.integer("BSPLINE rows", 2, 1024)? as usize;
                let cols = p.integer("BSPLINE cols", 2, 1024)? as usize;
                let su = p.integer("BSPLINE su", 2, 1024)? as usize;
                let sv = p.integer("BSPLINE sv", 2, 1024)? as usize;
                if rows < order || cols < order {
                    return Err(format!("{line}:{col}: BSPLINE needs at least `order` control points each way"));
                }
                let mut points = Vec::with_capacity(rows * cols);
                for _ in 0..rows * cols {
                    points.push(p.vec3("BSPLINE control point")?);
                }
                let patch = Patch { order, rows, cols, points };
                let before = scene.objects.len();
                for shape in patch.triangles(su, sv) {
                    references.push((s, line, col));
                    scene.objects.push(Object { shape, surface: 0 });
                }
                if scene.objects.len() == before {
                    return Err(format!("{line}:{col}: degenerate BSPLINE"));
                }
            }
            _ => return Err(format!("{line}:{col}: expected a keyword, found `{}`", p.tokens[p.pos - 1].text)),
        }
    }

    for (object, &(s, line, col)) in scene.objects.iter_mut().zip(&references) {
        object.surface = *surface_index.get(&s).ok_or_else(|| format!("{line}:{col}: surface {s} is not defined"))?;
    }

    let forward = scene.origin - scene.viewpoint;
    if forward.length() == 0.0 {
        return Err("1:1: VIEWPOINT equals ORIGIN".to_string());
    }
    if forward.cross(scene.upvector).length() == 0.0 {
        return Err("1:1: UPVECTOR is parallel to the view direction".to_string());
    }
    Ok(scene)
}

fn parse_shape(p: &mut Parser, keyword: &str, line: usize, col: usize) -> Result<Shape, String> {
    let positive = |v: f64| v > 0.0;
    let degenerate = || Err(format!("{line}:{col}: degenerate {keyword}"));
    Ok(match keyword {
        "SPHERE" => {
            let radius = p.checked("SPHERE radius", "> 0", positive)?;
            Shape::Sphere { centre: p.vec3("SPHERE centre")?, radius }
        }
        "BOX" => {
            let centre = p.vec3("BOX centre")?;
            let half = V3::new(
                p.checked("BOX half-size", "> 0", positive)?,
                p.checked("BOX half-size", "> 0", positive)?,
                p.checked("BOX half-size", "> 0", positive)?,
            );
            Shape::Box { centre, half }
        }
        "SUPERQUADRIC" => {
            let power = p.checked("SUPERQUADRIC power", "in 2..=64", |v| (2.0..=64.0).contains(&v))?;
            let centre = p.vec3("SUPERQUADRIC centre")?;
            let half = V3::new(
                p.checked("SUPERQUADRIC size", "> 0", positive)?,
                p.checked("SUPERQUADRIC size", "> 0", positive)?,
                p.checked("SUPERQUADRIC size", "> 0", positive)?,
            );
            Shape::Superquadric { power, centre, half }
        }
        "TRIANGLE" => {
            let pts = [p.vec3("TRIANGLE corner")?, p.vec3("TRIANGLE corner")?, p.vec3("TRIANGLE corner")?];
            let n = (pts[1] - pts[0]).cross(pts[2] - pts[0]);
            if n.length() == 0.0 {
                return degenerate();
            }
            Shape::Triangle { p: pts, normal: n.normalised() }
        }
        _ => {
            let pts = [
                p.vec3("RECTANGLE corner")?,
                p.vec3("RECTANGLE corner")?,
                p.vec3("RECTANGLE corner")?,
                p.vec3("RECTANGLE corner")?,
            ];
            // For a planar convex quad, the cross product of the diagonals
            // points to the side from which the corners run counter-clockwise.
            let n = (pts[2] - pts[0]).cross(pts[3] - pts[1]);
            if n.length() == 0.0 {
                return degenerate();
            }
            Shape::Rectangle { p: pts, normal: n.normalised() }
        }
    })
}

// ---------------------------------------------------------------------------
// B-spline patches
// ---------------------------------------------------------------------------

/// A tensor-product B-spline with clamped uniform knots, control points row
/// by row (`rows` along u, `cols` along v).
pub struct Patch {
    pub order: usize,
    pub rows: usize,
    pub cols: usize,
    pub points: Vec<V3>,
}

/// The clamped uniform knot vector for `n` control points of order `k`, in
/// knot units (spans of length 1, from 0 to n − k + 1).
fn knots(n: usize, k: usize) -> Vec<f64> {
    let m = (n - k + 1) as f64;
    (0..n + k).map(|j| (j as f64 - (k as f64 - 1.0)).clamp(0.0, m)).collect()
}

/// N_{i,k}(u) by the Cox–de Boor recursion, with the last span closed at
/// its right end so that u = end belongs to it.
fn basis_function(t: &[f64], i: usize, k: usize, u: f64) -> f64 {
    if k == 1 {
        let end = *t.last().unwrap_or(&0.0);
        let last_span = t[i + 1] == end && t[i] < end;
        return if (t[i] <= u && u < t[i + 1]) || (last_span && u == end) { 1.0 } else { 0.0 };
    }
    let mut value = 0.0;
    let left = t[i + k - 1] - t[i];
    if left > 0.0 {
        value += (u - t[i]) / left * basis_function(t, i, k - 1, u);
    }
    let right = t[i + k] - t[i + 1];
    if right > 0.0 {
        value += (t[i + k] - u) / right * basis_function(t, i + 1, k - 1, u);
    }
    value
}

/// dN_{i,k}/du.
fn basis_derivative(t: &[f64], i: usize, k: usize, u: f64) -> f64 {
    let mut value = 0.0;
    let left = t[i + k - 1] - t[i];
    if left > 0.0 {
        value += (k as f64 - 1.0) / left * basis_function(t, i, k - 1, u);
    }
    let right = t[i + k] - t[i + 1];
    if right > 0.0 {
        value -= (k as f64 - 1.0) / right * basis_function(t, i + 1, k - 1, u);
    }
    value
}

impl Patch {
    fn span(&self, n: usize) -> f64 {
        (n - self.order + 1) as f64
    }

    /// S(u, v), ∂S/∂u and ∂S/∂v at knot-unit parameters.
    pub fn evaluate(&self, u: f64, v: f64) -> (V3, V3, V3) {
        let (tu, tv) = (knots(self.rows, self.order), knots(self.cols, self.order));
        let zero = V3::new(0.0, 0.0, 0.0);
        let (mut s, mut su, mut sv) = (zero, zero, zero);
        for i in 0..self.rows {
            let (nu, du) = (basis_function(&tu, i, self.order, u), basis_derivative(&tu, i, self.order, u));
            for j in 0..self.cols {
                let (nv, dv) = (basis_function(&tv, j, self.order, v), basis_derivative(&tv, j, self.order, v));
                let p = self.points[i * self.cols + j];
                s = s + p * (nu * nv);
                su = su + p * (du * nv);
                sv = sv + p * (nu * dv);
            }
        }
        (s, su, sv)
    }

    /// The unit normal ∂S/∂u × ∂S/∂v, `None` where the derivatives vanish or
    /// are parallel (to 2^-20).
    fn exact_normal(&self, u: f64, v: f64) -> Option<V3> {
        let (_, su, sv) = self.evaluate(u, v);
        let n = su.cross(sv);
        (n.length() > su.length() * sv.length() * 2f64.powi(-20) && n.length() > 0.0).then(|| n.normalised())
    }

    /// Sample (l, k) of an su × sv grid: the point and its normal, the
    /// normal taken a little way into the patch (1/1024, then 1/64 of the
    /// shorter parameter range) where the surface has none.
    pub fn sample(&self, l: usize, su: usize, k: usize, sv: usize) -> (V3, Option<V3>) {
        let (mu, mv) = (self.span(self.rows), self.span(self.cols));
        let (u, v) = (l as f64 * mu / (su - 1) as f64, k as f64 * mv / (sv - 1) as f64);
        let inward = |t: f64, m: f64, step: f64| if t < m / 2.0 { t + step } else { t - step };
        let normal = self.exact_normal(u, v).or_else(|| {
            [1.0 / 1024.0, 1.0 / 64.0].iter().find_map(|f| {
                let step = mu.min(mv) * f;
                self.exact_normal(inward(u, mu, step), inward(v, mv, step))
            })
        });
        (self.evaluate(u, v).0, normal)
    }

    /// The triangles of the su × sv grid, quad by quad: (l,k), (l+1,k),
    /// (l,k+1) and (l+1,k), (l+1,k+1), (l,k+1); degenerate ones left out.
    pub fn triangles(&self, su: usize, sv: usize) -> Vec<Shape> {
        let mut out = Vec::new();
        for l in 0..su - 1 {
            for k in 0..sv - 1 {
                let c = |dl, dk| self.sample(l + dl, su, k + dk, sv);
                let (a, b, cc, d) = (c(0, 0), c(1, 0), c(0, 1), c(1, 1));
                for corners in [[a, b, cc], [b, d, cc]] {
                    let p = corners.map(|c| c.0);
                    let face = (p[1] - p[0]).cross(p[2] - p[0]);
                    if face.length() == 0.0 {
                        continue;
                    }
                    let face = face.normalised();
                    let normals = corners.map(|c| match c.1 {
                        Some(n) if n.dot(face) >= 0.0 => n,
                        Some(n) => -n,
                        None => face,
                    });
                    out.push(Shape::SmoothTriangle { p, normal: face, normals });
                }
            }
        }
        out
    }
}

/// Barycentric weights of `x` (on the plane of `p`), clamped to the triangle.
fn barycentric(p: &[V3; 3], x: V3) -> [f64; 3] {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let area = |a: V3, b: V3| (b - a).cross(x - a).dot(n).max(0.0);
    let w = [area(p[1], p[2]), area(p[2], p[0]), area(p[0], p[1])];
    let total = w[0] + w[1] + w[2];
    if total > 0.0 {
        w.map(|v| v / total)
    } else {
        [1.0, 0.0, 0.0]
    }
}

// ---------------------------------------------------------------------------
// Intersection
// ---------------------------------------------------------------------------

/// Which roots of a closed shape a ray may report.
#[derive(Clone, Copy, PartialEq)]
enum Roots {
    /// The nearest root with t > 0.
    Nearest,
    /// Only the far side: the ray starts on this shape and goes inward.
    FarOnly,
}

/// The parameter interval [t0, t1] where `o + t·d` is inside the box
/// |x_i − c_i| ≤ h_i, or `None` if the line misses it.
fn slab(o: V3, d: V3, c: V3, h: V3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..3 {
        let (oi, di) = (o.get(i) - c.get(i), d.get(i));
        let hi = h.get(i);
        if di == 0.0 {
            if oi.abs() > hi {
                return None;
            }
        } else {
            let (a, b) = ((-hi - oi) / di, (hi - oi) / di);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Bisect [lo, hi] while `is_lo_side(mid)` tells which half to keep, down to
/// adjacent floating-point numbers. Returns the final (lo, hi).
fn bisect(mut lo: f64, mut hi: f64, is_lo_side: impl Fn(f64) -> bool) -> (f64, f64) {
    for _ in 0..300 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if is_lo_side(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, hi)
}

fn sphere_hit(centre: V3, radius: f64, o: V3, d: V3, roots: Roots) -> Option<f64> {
    let oc = o - centre;
    let b = oc.dot(d);
    // Squared distance from the centre to the line, computed directly for accuracy.
    let perp = oc - d * b;
    let disc = radius * radius - perp.dot(perp);
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let (near, far) = (-b - sq, -b + sq);
    if roots == Roots::Nearest && near > 0.0 {
        Some(near)
    } else {
        (far > 0.0).then_some(far)
    }
}

fn box_hit(centre: V3, half: V3, o: V3, d: V3, roots: Roots) -> Option<f64> {
    let (t0, t1) = slab(o, d, centre, half)?;
    if roots == Roots::Nearest && t0 > 0.0 {
        Some(t0)
    } else {
        (t1 > 0.0).then_some(t1)
    }
}

fn superquadric_hit(power: f64, centre: V3, half: V3, o: V3, d: V3, roots: Roots) -> Option<f64> {
    // Work in local coordinates where the bounding box is [-1, 1]^3.
    let lo = V3::from_fn(|i| (o.get(i) - centre.get(i)) / half.get(i));
    let ld = V3::from_fn(|i| d.get(i) / half.get(i));
    let (t0, t1) = slab(lo, ld, V3::new(0.0, 0.0, 0.0), V3::new(1.0, 1.0, 1.0))?;
    if t1 <= 0.0 {
        return None;
    }
    let at = |t: f64| lo + ld * t;
    // f(t) = Σ|x_i|^p − 1 is convex along the line; f' is non-decreasing.
    let f = |t: f64| {
        let x = at(t);
        (0..3).map(|i| x.get(i).abs().powf(power)).sum::<f64>() - 1.0
    };
    let df = |t: f64| {
        let x = at(t);
        (0..3).map(|i| x.get(i).signum() * x.get(i).abs().powf(power - 1.0) * ld.get(i)).sum::<f64>()
    };
    let start = t0.max(0.0);
    // The minimum of f on [start, t1]: bisect on the sign of f'.
    let tmin = if df(start) >= 0.0 {
        start
    } else if df(t1) <= 0.0 {
        t1
    } else {
        let (a, b) = bisect(start, t1, |t| df(t) < 0.0);
        if f(a) <= f(b) {
            a
        } else {
            b
        }
    };
    if f(tmin) > 0.0 {
        return None; // the line never gets inside the surface within the box
    }
    if roots == Roots::Nearest {
        if f(start) > 0.0 {
            // Outside at the start: the entry root lies in [start, tmin].
            let (_, b) = bisect(start, tmin, |t| f(t) > 0.0);
            return Some(b);
        }
        if t0 > 0.0 {
            // Inside the surface right at the box entry (large p touches the
            // box faces at their centres): hit at the entry point.
            return Some(t0);
        }
        // Otherwise the ray starts inside the surface: report the exit.
    }
    let exit = if f(t1) <= 0.0 { t1 } else { bisect(tmin, t1, |t| f(t) <= 0.0).0 };
    (exit > 0.0).then_some(exit)
}

fn triangle_hit(p: &[V3; 3], o: V3, d: V3) -> Option<f64> {
    // Möller–Trumbore.
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - p[0];
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t > 0.0).then_some(t)
}

fn rectangle_hit(p: &[V3; 4], normal: V3, o: V3, d: V3) -> Option<f64> {
    let denom = normal.dot(d);
    if denom == 0.0 {
        return None;
    }
    let centre = (p[0] + p[1] + p[2] + p[3]) * 0.25;
    let t = normal.dot(centre - o) / denom;
    if t <= 0.0 {
        return None;
    }
    let hit = o + d * t;
    for k in 0..4 {
        let (a, b) = (p[k], p[(k + 1) % 4]);
        if (b - a).cross(hit - a).dot(normal) < 0.0 {
            return None;
        }
    }
    Some(t)
}

impl Object {
    fn hit(&self, o: V3, d: V3, roots: Roots) -> Option<f64> {
        match self.shape {
            Shape::Sphere { centre, radius } => sphere_hit(centre, radius, o, d, roots),
            Shape::Box { centre, half } => box_hit(centre, half, o, d, roots),
            Shape::Superquadric { power, centre, half } => superquadric_hit(power, centre, half, o, d, roots),
            Shape::Triangle { ref p, .. } | Shape::SmoothTriangle { ref p, .. } => triangle_hit(p, o, d),
            Shape::Rectangle { ref p, normal } => rectangle_hit(p, normal, o, d),
        }
    }

    /// The geometric unit normal at a point on the object (outward for closed
    /// shapes, the front normal for flat ones).
    fn normal(&self, at: V3) -> V3 {
        match self.shape {
            Shape::Sphere { centre, .. } => (at - centre).normalised(),
            Shape::Box { centre, half } => {
                let rel = |i: usize| (at.get(i) - centre.get(i)) / half.get(i);
                let mut axis = 0;
                for i in 1..3 {
                    if rel(i).abs() > rel(axis).abs() {
                        axis = i;
                    }
                }
                let sign = if rel(axis) < 0.0 { -1.0 } else { 1.0 };
                V3::from_fn(|i| if i == axis { sign } else { 0.0 })
            }
            Shape::Superquadric { power, centre, half } => {
                let g = V3::from_fn(|i| {
                    let x = (at.get(i) - centre.get(i)) / half.get(i);
                    x.signum() * x.abs().powf(power - 1.0) / half.get(i)
                });
                g.normalised()
            }
            Shape::Triangle { normal, .. } | Shape::Rectangle { normal, .. } | Shape::SmoothTriangle { normal, .. } => {
                normal
            }
        }
    }
}

/// Where a secondary ray starts: on object `object`, whose geometric normal
/// there is `normal`.
#[derive(Clone, Copy)]
struct Start {
    object: usize,
    normal: V3,
}

// ---------------------------------------------------------------------------
// Rendering
// ---------------------------------------------------------------------------

impl RefScene {
    /// The RASTER size (width, height).
    pub fn raster(&self) -> (u32, u32) {
        self.raster
    }

    /// The viewport (width, height) for an image of the given size.
    fn viewport_for(&self, width: u32, height: u32) -> (f64, f64) {
        self.viewport.unwrap_or_else(|| {
            let d = (self.origin - self.viewpoint).length();
            let vw = 2.0 * d * 30f64.to_radians().tan();
            (vw, vw * f64::from(height) / f64::from(width))
        })
    }

    /// The primary ray direction (unit) for a sample.
    fn primary_direction(&self, width: u32, height: u32, x: u32, y: u32, sx: u32, sy: u32) -> V3 {
        let n = f64::from(self.samples);
        let (vw, vh) = self.viewport_for(width, height);
        let f = (self.origin - self.viewpoint).normalised();
        let r = f.cross(self.upvector).normalised();
        let u = r.cross(f);
        let a = (f64::from(x) + (f64::from(sx) + 0.5) / n) / f64::from(width) - 0.5;
        let b = 0.5 - (f64::from(y) + (f64::from(sy) + 0.5) / n) / f64::from(height);
        let target = self.origin + r * (a * vw) + u * (b * vh);
        (target - self.viewpoint).normalised()
    }

    /// Unclamped linear colour of one primary ray sample for pixel (x,y),
    /// sub-cell (sx,sy) (for debugging).
    pub fn sample(&self, width: u32, height: u32, x: u32, y: u32, sx: u32, sy: u32) -> [f64; 3] {
        let d = self.primary_direction(width, height, x, y, sx, sy);
        self.trace(self.viewpoint, d, 0, None)
    }

    /// Render at width×height (the RASTER may be overridden; a default
    /// VIEWPORT then follows the new aspect ratio). Row-major, top row first.
    pub fn render(&self, width: u32, height: u32) -> Vec<[u8; 3]> {
        let n = self.samples;
        let mut image = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let mut sum = [0.0; 3];
                for sy in 0..n {
                    for sx in 0..n {
                        let c = self.sample(width, height, x, y, sx, sy);
                        sum = rgb_add(sum, c.map(|v| v.clamp(0.0, 1.0)));
                    }
                }
                let mean = rgb_scale(sum, 1.0 / f64::from(n * n));
                image.push(mean.map(|v| to_byte(v, self.gamma)));
            }
        }
        image
    }

    /// The nearest hit (t, object index) along the ray, ignoring what the
    /// start rule excludes; ties go to the earlier object.
    fn nearest(&self, o: V3, d: V3, start: Option<Start>) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for (i, object) in self.objects.iter().enumerate() {
            let Some(roots) = roots_for(object, i, d, start) else {
                continue;
            };
            if let Some(t) = object.hit(o, d, roots) {
                if best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, i));
                }
            }
        }
        best
    }

    /// True if any object is hit with 0 < t < max_t.
    fn blocked(&self, o: V3, d: V3, max_t: f64, start: Start) -> bool {
        self.objects.iter().enumerate().any(|(i, object)| {
            roots_for(object, i, d, Some(start)).and_then(|roots| object.hit(o, d, roots)).is_some_and(|t| t < max_t)
        })
    }

    /// The colour seen along the ray o + t·d (d unit length).
    fn trace(&self, o: V3, d: V3, depth: u32, start: Option<Start>) -> Rgb {
        let Some((t, index)) = self.nearest(o, d, start) else {
            return self.background;
        };
        let object = &self.objects[index];
        let surface = &self.surfaces[object.surface];
        let p = o + d * t;
        let ng = object.normal(p);
        let facing = if ng.dot(d) < 0.0 { ng } else { -ng };
        // A B-spline's triangle shades with its blended corner normals and
        // sends shadow rays from the point lifted onto the smooth surface.
        let (n, shadow_from) = match object.shape {
            Shape::SmoothTriangle { p: corners, normals, .. } => {
                let w = barycentric(&corners, p);
                let blend = (0..3).fold(V3::new(0.0, 0.0, 0.0), |acc, i| acc + normals[i] * w[i]);
                let blend = if blend.length() > 0.0 { blend.normalised() } else { ng };
                let n = if facing.dot(ng) < 0.0 { -blend } else { blend };
                let lifted = (0..3).fold(V3::new(0.0, 0.0, 0.0), |acc, i| {
                    acc + (p - normals[i] * (p - corners[i]).dot(normals[i])) * w[i]
                });
                (n, if (lifted - p).dot(facing) > 0.0 { lifted } else { p })
            }
            _ => (facing, p),
        };
        let v = -d;
        let here = Start { object: index, normal: ng };

        let mut local = surface.ambient;
        for light in &self.lights {
            let to_light = light.position - shadow_from;
            let dist = to_light.length();
            if dist == 0.0 {
                continue;
            }
            let lv = to_light * (1.0 / dist);
            let ndl = n.dot(lv);
            if ndl <= 0.0 || self.blocked(shadow_from, lv, dist, here) {
                continue;
            }
            let r = n * (2.0 * ndl) - lv;
            let rv = r.dot(v).max(0.0);
            let spec = if surface.exponent == 0.0 { 1.0 } else { rv.powf(surface.exponent) };
            let scale = light.brightness / (dist + self.attenuation);
            for (c, channel) in local.iter_mut().enumerate() {
                *channel += scale * (surface.diffuse[c] * ndl + surface.specular[c] * spec);
            }
        }

        let mut colour = rgb_scale(local, 1.0 - surface.transparency);
        if depth < self.rdepth {
            if surface.transparency != 0.0 {
                let behind = self.trace(p, d, depth + 1, Some(here));
                colour = rgb_add(colour, rgb_scale(behind, surface.transparency));
            }
            if surface.reflectivity != 0.0 {
                let rd = (n * (2.0 * n.dot(v)) - v).normalised();
                let reflected = self.trace(p, rd, depth + 1, Some(here));
                colour = rgb_add(colour, rgb_scale(reflected, surface.reflectivity));
            }
        }
        colour
    }
}

/// How object `i` may be hit by a ray with direction `d` that leaves `start`:
/// `None` if it cannot be hit at all (flat shape it starts on, or a closed
/// shape it leaves outward), `FarOnly` for a closed shape it enters.
fn roots_for(object: &Object, i: usize, d: V3, start: Option<Start>) -> Option<Roots> {
    match start {
        Some(s) if s.object == i => {
            if object.shape.is_flat() || d.dot(s.normal) >= 0.0 {
                None
            } else {
                Some(Roots::FarOnly)
            }
        }
        _ => Some(Roots::Nearest),
    }
}

/// Gamma-correct a mean (already clamped) channel value and round half up.
fn to_byte(v: f64, gamma: f64) -> u8 {
    let g = v.clamp(0.0, 1.0).powf(1.0 / gamma);
    (255.0 * g + 0.5).floor().clamp(0.0, 255.0) as u8
}

// ---------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------

#[cfg(test)]
mod tests {
    use super::*;

    fn centre_pixel(scene: &RefScene, w: u32, h: u32) -> [u8; 3] {
        scene.render(w, h)[(h / 2 * w + w / 2) as usize]
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9)
    }

    #[test]
    fn single_sphere_centre_pixel() {
        // Camera (0,0,10) looking at a unit sphere at the origin; a 3×3
        // raster puts the centre pixel's ray exactly on the axis, hitting
        // P = (0,0,1) with N = (0,0,1). Light at (0,0,10): d = 9, N·L = 1,
        // R·V = 1, so C = a + 1/(9+1)·(diffuse + specular).
        let scene = parse(
            "RASTER 3 3 GAMMA 1 LIGHT 1 0 0 10
             SPHERE 1 1 0 0 0
             SURFACE 1 0.1 0.2 0.0  0.5 0.3 0.8  0.2 0.1 0.0  10 0 0",
        )
        .unwrap();
        let c = scene.sample(3, 3, 1, 1, 0, 0);
        assert!(close(c, [0.17, 0.24, 0.08]), "{c:?}");
        // 255·0.17 = 43.35, 255·0.24 = 61.2, 255·0.08 = 20.4
        assert_eq!(centre_pixel(&scene, 3, 3), [43, 61, 20]);
        // The same with the default gamma 2.2.
        let g = parse(
            "RASTER 3 3 LIGHT 1 0 0 10 SPHERE 1 1 0 0 0
             SURFACE 1 0.1 0.2 0.0  0.5 0.3 0.8  0.2 0.1 0.0  10 0 0",
        )
        .unwrap();
        let expect = [0.17f64, 0.24, 0.08].map(|v| (255.0 * v.powf(1.0 / 2.2) + 0.5).floor() as u8);
        assert_eq!(centre_pixel(&g, 3, 3), expect);
        assert_eq!(expect, [114, 133, 81]);
        // A corner pixel misses the sphere.
        assert_eq!(scene.render(3, 3)[0], [0, 0, 0]);
    }

    #[test]
    fn background_only() {
        let scene = parse("BACKGROUND 0.5 0.25 1 GAMMA 1").unwrap();
        assert_eq!(scene.raster(), (320, 240));
        let image = scene.render(8, 6);
        assert_eq!(image.len(), 48);
        // 127.5 and 63.75 round half up.
        assert!(image.iter().all(|&p| p == [128, 64, 255]));
        // An empty file renders black.
        assert!(parse("").unwrap().render(4, 4).iter().all(|&p| p == [0, 0, 0]));
    }

    #[test]
    fn tie_goes_to_earlier_object() {
        let tri = |s: u32| format!("TRIANGLE {s} -5 -5 0  5 -5 0  0 5 0\n");
        let surfaces = "SURFACE 1 1 0 0  0 0 0  0 0 0  0 0 0
                        SURFACE 2 0 1 0  0 0 0  0 0 0  0 0 0
                        GAMMA 1 RASTER 3 3";
        let a = parse(&format!("{}{}{surfaces}", tri(1), tri(2))).unwrap();
        let b = parse(&format!("{}{}{surfaces}", tri(2), tri(1))).unwrap();
        assert_eq!(centre_pixel(&a, 3, 3), [255, 0, 0]);
        assert_eq!(centre_pixel(&b, 3, 3), [0, 255, 0]);
        // Two identical spheres.
        let c = parse(&format!("SPHERE 2 1 0 0 0 SPHERE 1 1 0 0 0 {surfaces}")).unwrap();
        assert_eq!(centre_pixel(&c, 3, 3), [0, 255, 0]);
    }

    #[test]
    fn superquadric_p2_matches_sphere() {
        let rest = "VIEWPOINT 1 2 9 LIGHT 1 -4 5 6 LIGHT 0.5 5 1 3 BACKGROUND 0.1 0.1 0.2
                    SURFACE 1 0.05 0.05 0.05  0.7 0.4 0.2  0.5 0.5 0.5  20 0.2 0
                    TRIANGLE 1 -9 -1.5 9  9 -1.5 9  0 -1.5 -9";
        let sphere = parse(&format!("SPHERE 1 1.5 0.2 0.1 0 {rest}")).unwrap();
        let sq = parse(&format!("SUPERQUADRIC 1 2 0.2 0.1 0  1.5 1.5 1.5 {rest}")).unwrap();
        let (a, b) = (sphere.render(64, 48), sq.render(64, 48));
        let mut lit = 0;
        for (pa, pb) in a.iter().zip(&b) {
            for c in 0..3 {
                assert!(pa[c].abs_diff(pb[c]) <= 1, "{pa:?} vs {pb:?}");
            }
            lit += usize::from(pa[0] > 60);
        }
        assert!(lit > 100, "the sphere should cover part of the image");
    }

    #[test]
    fn superquadric_large_power_hits_face_centre() {
        // Head-on, the centre ray of a p = 64 superquadric meets it where it
        // touches its bounding box: same colour as a box there.
        let rest = "RASTER 3 3 GAMMA 1 LIGHT 1 0 0 10
                    SURFACE 1 0.1 0.1 0.1  0.5 0.5 0.5  0 0 0  0 0 0";
        let sq = parse(&format!("SUPERQUADRIC 1 64 0 0 0 1 1 1 {rest}")).unwrap();
        let bx = parse(&format!("BOX 1 0 0 0 1 1 1 {rest}")).unwrap();
        let (a, b) = (sq.sample(3, 3, 1, 1, 0, 0), bx.sample(3, 3, 1, 1, 0, 0));
        assert!(close(a, b), "{a:?} vs {b:?}");
        assert!(close(a, [0.15; 3]), "{a:?}");
        // A non-integer power renders something too.
        let nf = parse(&format!("SUPERQUADRIC 1 3.7 0 0 0 1 1 1 {rest}")).unwrap();
        assert!(close(nf.sample(3, 3, 1, 1, 0, 0), [0.15; 3]));
    }

    #[test]
    fn shadow_occlusion() {
        // Ground z = 0 facing the camera; light at (5,0,5); a small sphere
        // at (2.5,0,2.5) sits on the segment from (0,0,0) to the light but
        // off the camera's centre ray.
        let base = "RASTER 3 3 GAMMA 1 LIGHT 1 5 0 5
                    RECTANGLE 1 -9 -9 0  9 -9 0  9 9 0  -9 9 0
                    SURFACE 1 0.1 0.1 0.1  0.5 0.5 0.5  0 0 0  0 0 0";
        let shadowed = |t: &str| {
            let s = parse(&format!("{base} SPHERE 2 0.5 2.5 0 2.5 SURFACE 2 1 1 1 1 1 1 0 0 0 0 0 {t}")).unwrap();
            s.sample(3, 3, 1, 1, 0, 0)
        };
        assert!(close(shadowed("0"), [0.1; 3]));
        // Transparent objects cast shadows too.
        assert!(close(shadowed("1"), [0.1; 3]));
        // Without the sphere the point is lit: d = √50, N·L = 1/√2.
        let lit = parse(base).unwrap().sample(3, 3, 1, 1, 0, 0);
        let d = 50f64.sqrt();
        let expect = 0.1 + 1.0 / (d + 1.0) * 0.5 / 2f64.sqrt();
        assert!(close(lit, [expect; 3]), "{lit:?}");
    }

    #[test]
    fn transparent_sphere_and_depth() {
        // A fully transparent sphere: the ray enters, reaches the far side
        // (not the near root again) and leaves into the background.
        let scene = |depth: u32| {
            parse(&format!(
                "RASTER 3 3 GAMMA 1 RDEPTH {depth} BACKGROUND 0.2 0.4 0.6
                 SPHERE 1 1 0 0 0 SURFACE 1 0.5 0.5 0.5 0 0 0 0 0 0 0 0 1"
            ))
            .unwrap()
            .sample(3, 3, 1, 1, 0, 0)
        };
        assert!(close(scene(2), [0.2, 0.4, 0.6]));
        assert!(close(scene(3), [0.2, 0.4, 0.6]));
        // Depth 1: the transmitted ray reaches the back face, which may not
        // recurse further; its local colour is weighted by 1 − t = 0.
        assert!(close(scene(1), [0.0; 3]));
        assert!(close(scene(0), [0.0; 3]));
    }

    #[test]
    fn mirror_reflects_background() {
        // A mirror triangle facing the camera reflects the ray straight back:
        // nothing is behind the camera, so it sees the background.
        let s = parse(
            "RASTER 3 3 GAMMA 1 BACKGROUND 0.3 0.3 0.3
             TRIANGLE 1 -5 -5 0 5 -5 0 0 5 0
             SURFACE 1 0.1 0.1 0.1 0 0 0 0 0 0 0 0.5 0",
        )
        .unwrap();
        assert!(close(s.sample(3, 3, 1, 1, 0, 0), [0.25; 3]));
    }

    #[test]
    fn parsing_rules() {
        let s = parse(
            "/* comment
                over lines */ viewpoint 1 +2.5E2 .25 // rest of line
             Raster 4 2 samples 2 imagefile \"my file.png\" Light 1e-3 0 0 0
             surface 3 0 0 0 0 0 0 0 0 0 0 0 0 sphere 3 1 0 0 -5",
        )
        .unwrap();
        assert_eq!(s.viewpoint, V3::new(1.0, 250.0, 0.25));
        assert_eq!(s.raster(), (4, 2));
        assert_eq!(s.samples, 2);
        assert_eq!(s.imagefile.as_deref(), Some("my file.png"));
        assert_eq!(s.lights[0].brightness, 1e-3);
        assert_eq!(s.render(4, 2).len(), 8);

        let err = |text: &str| parse(text).unwrap_err();
        assert!(err("SPHERE 1 1 0 0 0\n  FOO").starts_with("2:3:"), "{}", err("\n  FOO"));
        assert!(err("RASTER 3 nan").starts_with("1:10:"));
        assert!(err("GAMMA 0x10").starts_with("1:7:"));
        assert!(err("RASTER 3.5 2").starts_with("1:8:"));
        assert!(err("\n/* open").starts_with("2:1:"));
        assert!(err("SPHERE 1 1 0 0 0").contains("surface 1"));
        assert!(err("GAMMA 1\nGAMMA 2").contains("lines 1 and 2"));
        assert!(err("SPHERE 1 1 0 0").contains("end of file"));
        assert!(err("BSPLINE 1 2").contains("BSPLINE"));
        assert!(err("BSPLINE 1 3 2 3 4 4").contains("BSPLINE"));
    }

    #[test]
    fn default_viewport_follows_render_aspect() {
        // A pixel's horizontal extent must not depend on the render height.
        let s = parse("").unwrap();
        let d1 = s.primary_direction(320, 240, 0, 120, 0, 0);
        let d2 = s.primary_direction(320, 100, 0, 50, 0, 0);
        assert!((d1.x - d2.x).abs() < 1e-12);
        // The left edge of the viewport is at −d·tan30° = −10·tan30°.
        let left = s.primary_direction(1_000_000, 1, 0, 0, 0, 0);
        assert!((left.x / left.z - 30f64.to_radians().tan()).abs() < 1e-5);
    }
}
