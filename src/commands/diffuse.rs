//! `toposmooth diffuse IMAGE_OR_MESH --colors colors.json -o out.png`: colour diffusion from
//! coloured points with monotone weights (a convex blend: no pixel leaves the colours' box).

use super::sig6;
use super::weights::stage_weights;
use crate::apps::diffuse::{
    blend, linear_to_srgb8, outside_box, parse_colors, pixel_mesh, ColorAt, ColorPoint, PixelMesh,
};
use crate::apps::handles::{resolve, Handle, HandleShape};
use crate::apps::weights::{weights, WeightMethod, WeightSettings};
use crate::domain::{Domain, TriMesh};
use crate::error::{Error, Result};
use crate::io::import::read_trimesh;
use crate::io::{stage_with, Staged};
use crate::plot::{plot_mesh_colours, MeshView};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of `diffuse`.
#[derive(Clone, Debug)]
pub struct DiffuseArgs {
    /// An image (PNG, TIFF: its alpha ≥ 128 is the shape) or a mesh.
    pub input: PathBuf,
    /// colors.json.
    pub colors: PathBuf,
    /// Output: PNG for an image, .vtu/.vtp/.ply (arrays red, green, blue and the weights) for a mesh.
    pub output: PathBuf,
    /// Where an image's Float64 weights go (.vtu, .vtp, .ply); default `<output>_weights.vtu`.
    pub weights: Option<PathBuf>,
    /// Method and order of the weights.
    pub settings: WeightSettings,
    /// Enlarged picture with the colour points marked.
    pub plot: Option<PathBuf>,
    /// Report JSON.
    pub report: Option<PathBuf>,
    /// Camera of a mesh picture.
    pub view: MeshView,
}

fn is_image(path: &Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    matches!(ext.as_str(), "png" | "tif" | "tiff")
}

#[derive(serde::Serialize)]
struct DiffuseReport {
    input_file: String,
    colors_file: String,
    vertices: usize,
    method: WeightMethod,
    order: u8,
    certified: Vec<bool>,
    spurious_exact: Vec<usize>,
    outside_box: usize,
    dropped_pixels: usize,
    max_normalisation_change: f64,
    seconds: f64,
}

/// Runs `diffuse`.
pub fn diffuse(args: &DiffuseArgs) -> Result<String> {
    let start = Instant::now();
    let weights_path = args.weights.clone().unwrap_or_else(|| {
        let stem = args.output.file_stem().unwrap_or_default().to_string_lossy().to_string();
        args.output.with_file_name(format!("{stem}_weights.vtu"))
    });
    super::check_distinct(
        &[args.input.as_path(), args.colors.as_path()],
        &[
            ("-o", Some(&args.output)),
            ("--weights", is_image(&args.input).then_some(weights_path.as_path())),
            ("--plot", args.plot.as_deref()),
            ("--report", args.report.as_deref()),
        ],
    )?;
    let text =
        std::fs::read_to_string(&args.colors).map_err(|source| Error::Io { path: args.colors.clone(), source })?;
    let points = parse_colors(&text).map_err(|e| e.in_file(&args.colors))?;
    let image = is_image(&args.input);
    if image {
        crate::io::export::check_mesh_output(&weights_path)?;
    }
    if !image && args.weights.is_some() {
        return Err(Error::Usage(
            "--weights is for images; on a mesh the weights are written into the -o file beside red, green, blue"
                .into(),
        ));
    }
    let (read, pm): (Option<TriMesh>, Option<PixelMesh>) = if image {
        (None, Some(read_pixel_mesh(&args.input)?))
    } else {
        crate::io::export::check_mesh_output(&args.output)?;
        (Some(read_trimesh(&args.input)?.0), None)
    };
    let mesh: &TriMesh = match (&read, &pm) {
        (Some(m), _) => m,
        (None, Some(pm)) => &pm.mesh,
        (None, None) => unreachable!("an image gives a pixel mesh, a mesh file a mesh"),
    };
    if image && !args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return Err(Error::Usage(format!("{}: the diffused image is written as PNG", args.output.display())));
    }
    let handles = color_handles(&points, pm.as_ref(), &args.colors)?;
    let sets = resolve(mesh, &handles).map_err(|e| e.in_file(&args.colors))?;
    let w = weights(mesh, &sets, &args.settings).map_err(|e| e.in_file(&args.input))?;
    let rgbs: Vec<[u8; 3]> = points.iter().map(|p| p.rgb).collect();
    let lin = blend(&w.normalised, &rgbs);
    let colours: Vec<[u8; 3]> = lin.iter().map(|c| c.map(linear_to_srgb8)).collect();
    let outside = outside_box(&rgbs, &colours);
    let names: Vec<String> = points.iter().map(|p| p.name.clone()).collect();

    let diffused =
        Diffused { mesh, pm: pm.as_ref(), weights: &w, names: &names, colours: &colours, sets: &sets, rgbs: &rgbs };
    let (mut staged, mut wrote) = stage_diffused(args, &diffused, &weights_path)?;
    if let Some(path) = &args.report {
        let report = DiffuseReport {
            input_file: args.input.display().to_string(),
            colors_file: args.colors.display().to_string(),
            vertices: mesh.n_vertices(),
            method: args.settings.method,
            order: args.settings.order,
            certified: w.functions.iter().map(|f| f.certificate.passed).collect(),
            spurious_exact: w.functions.iter().map(|f| f.spurious.exact).collect(),
            outside_box: outside,
            dropped_pixels: pm.as_ref().map_or(0, |p| p.dropped),
            max_normalisation_change: w.max_normalisation_change,
            seconds: start.elapsed().as_secs_f64(),
        };
        staged.push(super::stage_report(path, &report)?);
        wrote.push(super::shown(path));
    }
    crate::io::commit_all(staged)?;
    let certified = w.functions.iter().filter(|f| f.certificate.passed).count();
    let spurious: usize = w.functions.iter().map(|f| f.spurious.exact).sum();
    let mut text = format!(
        "{}: {} colour points on {} {}; {} weights of order {}: {certified} of {} certified, {spurious} spurious extrema\n",
        args.input.display(),
        points.len(),
        mesh.n_vertices(),
        if image { "pixels" } else { "vertices" },
        format!("{:?}", args.settings.method).to_lowercase(),
        args.settings.order,
        w.functions.len()
    );
    if let Some(pm) = &pm {
        if pm.dropped > 0 {
            text += &format!(
                "note: {} shape pixels outside any 2 × 2 block of the shape were left transparent\n",
                pm.dropped
            );
        }
    }
    text += &format!(
        "{outside} of {} {} outside the per-channel box of the given colours (8-bit output); largest normalisation change {}; {} s\n",
        colours.len(),
        if image { "pixels" } else { "vertices" },
        sig6(w.max_normalisation_change),
        sig6(start.elapsed().as_secs_f64())
    );
    text += &format!("wrote {}\n", wrote.join(", "));
    Ok(text)
}

/// The image's pixels inside its shape (alpha ≥ 128, or every pixel without alpha) as a
/// triangulated pixel mesh.
fn read_pixel_mesh(path: &Path) -> Result<PixelMesh> {
    let img = image::ImageReader::open(path)
        .map_err(|source| Error::Io { path: path.to_path_buf(), source })?
        .with_guessed_format()
        .map_err(|source| Error::Io { path: path.to_path_buf(), source })?
        .decode()
        .map_err(|e| Error::input(format!("cannot decode the image: {e}")).in_file(path))?;
    let has_alpha = img.color().has_alpha();
    let rgba = img.to_rgba8();
    let (w, h) = (rgba.width() as usize, rgba.height() as usize);
    let inside: Vec<bool> = rgba.pixels().map(|p| !has_alpha || p.0[3] >= 128).collect();
    pixel_mesh(w, h, &inside).map_err(|e| e.in_file(path))
}

/// The colour points as handles: a pixel of the image (inside its shape), or a vertex or a
/// point of the mesh.
fn color_handles(points: &[ColorPoint], pm: Option<&PixelMesh>, colors: &Path) -> Result<Vec<Handle>> {
    let mut handles = Vec::with_capacity(points.len());
    for p in points {
        let shape = match (p.at, pm) {
            (ColorAt::Pixel([c, r]), Some(pm)) => {
                if c >= pm.width || r >= pm.height {
                    return Err(Error::input(format!(
                        "point `{}`: pixel [{c}, {r}] is outside the {} × {} image",
                        p.name, pm.width, pm.height
                    ))
                    .in_file(colors));
                }
                let v = pm.vertex_of_pixel[r * pm.width + c].ok_or_else(|| {
                    Error::input(format!(
                        "point `{}`: pixel [{c}, {r}] is outside the image's shape (alpha < 128)",
                        p.name
                    ))
                    .in_file(colors)
                })?;
                HandleShape::Vertices(vec![v])
            }
            (ColorAt::Pixel(_), None) => {
                return Err(Error::input(format!(
                    "point `{}`: a mesh takes \"vertex\" or \"point\", not \"pixel\"",
                    p.name
                ))
                .in_file(colors))
            }
            (_, Some(_)) => {
                return Err(Error::input(format!("point `{}`: an image takes \"pixel\": [column, row]", p.name))
                    .in_file(colors))
            }
            (ColorAt::Vertex(v), None) => HandleShape::Vertices(vec![v]),
            (ColorAt::Point(q), None) => HandleShape::Point(q),
        };
        handles.push(Handle { name: p.name.clone(), shape });
    }
    Ok(handles)
}

/// A diffusion's result, for its outputs.
struct Diffused<'a> {
    mesh: &'a TriMesh,
    pm: Option<&'a PixelMesh>,
    weights: &'a crate::apps::weights::Weights,
    names: &'a [String],
    colours: &'a [[u8; 3]],
    sets: &'a [Vec<usize>],
    rgbs: &'a [[u8; 3]],
}

/// Stages the outputs: for an image the PNG, the weights mesh and the enlarged picture; for a
/// mesh the mesh with red, green, blue and the weights, and its picture. Returns them with
/// the names written.
fn stage_diffused(args: &DiffuseArgs, d: &Diffused, weights_path: &Path) -> Result<(Vec<Staged>, Vec<String>)> {
    let mut staged: Vec<Staged> = Vec::new();
    let mut wrote = vec![super::shown(&args.output)];
    match d.pm {
        Some(pm) => {
            let mut img = image::RgbaImage::new(pm.width as u32, pm.height as u32);
            for (v, c) in d.colours.iter().enumerate() {
                let p = pm.pixel_of_vertex[v];
                img.put_pixel((p % pm.width) as u32, (p / pm.width) as u32, image::Rgba([c[0], c[1], c[2], 255]));
            }
            staged.push(stage_png(&args.output, &img)?);
            let wpath = weights_path.to_path_buf();
            staged.push(stage_weights(&wpath, d.mesh, d.names, d.weights)?);
            wrote.push(super::shown(&wpath));
            if let Some(path) = &args.plot {
                staged.push(stage_png(path, &enlarged(&img, pm, d.sets, d.rgbs))?);
                wrote.push(super::shown(path));
            }
        }
        None => {
            let chan = |k: usize| -> Vec<f64> { d.colours.iter().map(|c| f64::from(c[k])).collect() };
            let (r, g, b) = (chan(0), chan(1), chan(2));
            let mut owned: Vec<(String, Vec<f64>)> = vec![("red".into(), r), ("green".into(), g), ("blue".into(), b)];
            owned.extend(super::weights::weight_arrays(d.mesh, d.names, d.weights));
            let arrays: Vec<(&str, &[f64])> = owned.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect();
            staged.push(crate::io::export::stage_mesh(&args.output, d.mesh, &arrays)?);
            if let Some(path) = &args.plot {
                let name = |p: &Path| p.file_name().unwrap_or_default().to_string_lossy().to_string();
                let title = format!("{} coloured by {}", name(&args.input), name(&args.colors));
                let view = if d.mesh.is_planar() { MeshView { azimuth: 0.0, elevation: 90.0 } } else { args.view };
                staged.push(super::stage_plot(path, |p| {
                    plot_mesh_colours(p, d.mesh.positions(), d.mesh.faces(), d.colours, &title, view)
                })?);
                wrote.push(super::shown(path));
            }
        }
    }
    Ok((staged, wrote))
}

/// Stages a PNG and reads it back before commit (certificate item 5: every pixel as coloured).
fn stage_png(path: &Path, img: &image::RgbaImage) -> Result<Staged> {
    let staged = stage_with(path, |w| {
        img.write_to(w, image::ImageFormat::Png).map_err(|e| std::io::Error::other(e.to_string()))
    })?;
    check_png_written(&staged, img)?;
    Ok(staged)
}

fn check_png_written(staged: &Staged, img: &image::RgbaImage) -> Result<()> {
    let fail = |what: String| Error::Uncertified {
        path: Some(staged.target().to_path_buf()),
        message: format!("certificate item 5: the image as written reads back with {what}"),
    };
    // the temporary's name has no .png: the format is the content's
    let decoded = image::ImageReader::open(staged.temp_path())
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| fail(format!("an error: {e}")))?
        .decode();
    let read = decoded.map_err(|e| fail(format!("an error: {e}")))?.into_rgba8();
    if read.dimensions() != img.dimensions() {
        let ((w, h), (w0, h0)) = (read.dimensions(), img.dimensions());
        return Err(fail(format!("{w} × {h} pixels instead of {w0} × {h0}")));
    }
    match read.pixels().zip(img.pixels()).position(|(a, b)| a != b) {
        Some(i) => Err(fail(format!("another colour at pixel {i}"))),
        None => Ok(()),
    }
}

/// The image enlarged (nearest neighbour, at least 600 pixels wide) on a checkerboard, with
/// each colour point drawn as a ring.
fn enlarged(img: &image::RgbaImage, pm: &PixelMesh, sets: &[Vec<usize>], rgbs: &[[u8; 3]]) -> image::RgbaImage {
    let s = (600 / pm.width.max(1)).clamp(1, 16) as u32;
    let (w, h) = (img.width() * s, img.height() * s);
    let mut out = image::RgbaImage::from_fn(w, h, |x, y| {
        let p = img.get_pixel(x / s, y / s);
        if p.0[3] == 0 {
            let g = if ((x / 8) + (y / 8)) % 2 == 0 { 235 } else { 250 };
            image::Rgba([g, g, g, 255])
        } else {
            *p
        }
    });
    let radius = (3 * s).max(6) as i64;
    for (set, rgb) in sets.iter().zip(rgbs) {
        let p = pm.pixel_of_vertex[set[0]];
        let (cx, cy) =
            (((p % pm.width) as i64) * s as i64 + s as i64 / 2, ((p / pm.width) as i64) * s as i64 + s as i64 / 2);
        for dy in -radius - 2..=radius + 2 {
            for dx in -radius - 2..=radius + 2 {
                let d = ((dx * dx + dy * dy) as f64).sqrt();
                let (x, y) = (cx + dx, cy + dy);
                if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
                    continue;
                }
                let c = if d <= radius as f64 - 1.5 {
                    image::Rgba([rgb[0], rgb[1], rgb[2], 255])
                } else if d <= radius as f64 + 1.5 {
                    image::Rgba([0, 0, 0, 255])
                } else {
                    continue;
                };
                out.put_pixel(x as u32, y as u32, c);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_png_that_reads_back_otherwise_is_refused() {
        let dir = std::env::temp_dir().join(format!("toposmooth-png-readback-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let img = image::RgbaImage::from_fn(5, 3, |x, y| image::Rgba([x as u8 * 50, y as u8 * 80, 7, 255]));
        let staged = stage_png(&dir.join("d.png"), &img).unwrap();
        assert!(check_png_written(&staged, &img).is_ok());
        // the same image with one pixel one step off: refused, naming the target
        let mut other = img.clone();
        other.get_pixel_mut(4, 2).0[2] = 8;
        let e = check_png_written(&staged, &other).unwrap_err().to_string();
        assert!(e.contains("certificate item 5") && e.contains("pixel 14") && e.contains("d.png"), "{e}");
        let e = check_png_written(&staged, &image::RgbaImage::new(3, 5)).unwrap_err().to_string();
        assert!(e.contains("5 × 3 pixels instead of 3 × 5"), "{e}");
        drop(staged);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
