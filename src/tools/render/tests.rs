//! Tests of the pictures: layout, colours, depth, animations.

use super::*;
use crate::model::particles::Particle;

#[test]
fn a_sphere_is_drawn_in_the_middle() {
    let style = Style {
        width: 320,
        height: 240,
        color: ColorBy::Speed,
        view: View::Iso,
        scale_bar: true,
    };
    let img = render(&one(DVec3::ZERO, DVec3::ZERO), &Mesh::default(), &style).unwrap();
    assert_eq!(img.dimensions(), (320, 240));
    // The scene is left of the colour bar and below the line of the time stamp.
    assert_ne!(*img.get_pixel(139, 127), BACKGROUND);
    assert_eq!(*img.get_pixel(0, 0), BACKGROUND);
    assert!(
        render(
            &one(DVec3::ZERO, DVec3::ZERO),
            &Mesh::default(),
            &Style { width: 10, ..style }
        )
        .is_err()
    );
}

fn one(x: DVec3, v: DVec3) -> Particles {
    [Particle {
        x,
        radius: 1.0,
        v,
        ..Default::default()
    }]
    .into_iter()
    .collect()
}

/// A 400 x 300 picture from the front, coloured by `color`.
fn front(color: ColorBy) -> Style {
    Style {
        width: 400,
        height: 300,
        color,
        view: View::Front,
        scale_bar: false,
    }
}

/// In one layout the view and the colour bar stay put: a slow particle that moved has
/// its speed's colour on the bar of the fast one, the bar and the frame do not change.
#[test]
fn one_layout_keeps_the_view_and_the_colours() {
    let style = front(ColorBy::Speed);
    let a = one(DVec3::ZERO, DVec3::new(4.0, 0.0, 0.0));
    let b = one(DVec3::new(5.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
    let mut layout = Layout::of(&a, &Mesh::default(), &style);
    layout.include(&b, &Mesh::default(), &style);
    assert_eq!(layout.range(), (0.0, 4.0));
    let ia = render_in(&a, &Mesh::default(), &style, &layout, Some(0.0)).unwrap();
    let ib = render_in(&b, &Mesh::default(), &style, &layout, Some(0.0)).unwrap();
    // The colour bar and its labels (right of the scene) are the same pixels.
    for y in 0..300 {
        for x in 362..400 {
            assert_eq!(ia.get_pixel(x, y), ib.get_pixel(x, y), "({x}, {y})");
        }
    }
    // The particles are where they are, not each re-centred: a left of b.
    let centre_x = |img: &RgbImage| {
        let xs: Vec<u32> = (0..300)
            .flat_map(|x| (20..300).map(move |y| (x, y)))
            .filter(|&(x, y)| *img.get_pixel(x, y) != BACKGROUND)
            .map(|(x, _)| x)
            .collect();
        xs.iter().sum::<u32>() as f64 / xs.len() as f64
    };
    assert!(centre_x(&ia) + 100.0 < centre_x(&ib));
    // A fixed range and box replace the fitted ones.
    layout.fix(
        &Fixed {
            bounds: Some((DVec3::splat(-10.0), DVec3::splat(10.0))),
            range: Some((0.0, 10.0)),
        },
        &style,
    );
    assert_eq!(layout.range(), (0.0, 10.0));
    assert_eq!(layout.bounds().0.x, -10.0);
}

#[test]
fn categories_get_a_legend_with_names() {
    let style = front(ColorBy::Material);
    let mut p = one(DVec3::ZERO, DVec3::ZERO);
    p.material[0] = 1;
    let mut layout = Layout::of(&p, &Mesh::default(), &style);
    layout.material_names = vec!["glass".into(), "steel".into()];
    assert_eq!(layout.label(ColorBy::Material, 1), "1 steel");
    let img = render_in(&p, &Mesh::default(), &style, &layout, None).unwrap();
    let swatch = rgb(category_colour(1));
    assert!(img.pixels().filter(|&&c| c == swatch).count() >= 64);
}

/// Two unit spheres side by side (x = 0 and 3) and mesh edges along z = 0, behind them
/// (y = 2) or in front (y = -2), seen from the front (-y); the face's other edges run down
/// and out of the view (not under the title of the colour bar).
fn spheres_and_an_edge(y: f64) -> (RgbImage, RgbImage) {
    let style = front(ColorBy::Speed);
    let mut p = one(DVec3::ZERO, DVec3::ZERO);
    p.push(one(DVec3::new(3.0, 0.0, 0.0), DVec3::ZERO).get(0));
    let off = format!("OFF\n3 1 0\n-3 {y} 0\n6 {y} 0\n1.5 {y} -5\n3 0 1 2\n");
    let mesh = Mesh::parse_off(&off, "t.off", &[0.0]).unwrap();
    // (One view for both: the mesh widens it.)
    let layout = Layout::of(&p, &mesh, &style);
    let plain = render_in(&p, &Mesh::default(), &style, &layout, None).unwrap();
    (plain, render_in(&p, &mesh, &style, &layout, None).unwrap())
}

/// The pixels where the second picture differs from the first, and of those the ones where
/// the first shows a sphere.
fn drawn_over(plain: &RgbImage, with: &RgbImage) -> (usize, usize) {
    let drawn: Vec<(u32, u32)> = (plain.enumerate_pixels())
        .filter(|(x, y, c)| with.get_pixel(*x, *y) != *c)
        .map(|(x, y, _)| (x, y))
        .collect();
    let over = drawn
        .iter()
        .filter(|(x, y)| *plain.get_pixel(*x, *y) != BACKGROUND)
        .count();
    (drawn.len(), over)
}

#[test]
fn edges_behind_a_sphere_are_hidden_and_in_front_drawn() {
    let (plain, behind) = spheres_and_an_edge(2.0);
    let (drawn, over) = drawn_over(&plain, &behind);
    // The edge shows between and beside the spheres, never across them.
    assert!(drawn > 40, "{drawn}");
    assert_eq!(over, 0);
    let (plain, front) = spheres_and_an_edge(-2.0);
    let (drawn, over) = drawn_over(&plain, &front);
    assert!(drawn > 40 && over > 40, "{drawn} {over}");
}

#[test]
fn gif_frames_are_dithered_without_bands() {
    // A colour map along y shaded from dark to light along x, as on many spheres.
    let img = RgbImage::from_fn(256, 64, |x, y| {
        let s = y as f64 / 63.0;
        let hue = [0.27 + 0.7 * s, 0.0 + 0.9 * s.sqrt(), 0.33 + 0.3 * (1.0 - s)];
        let shade = 0.35 + 0.65 * x as f64 / 255.0;
        Rgb(hue.map(|c| (255.0 * c * shade).round() as u8))
    });
    let out = dithered(img.clone());
    let colours: std::collections::HashSet<[u8; 4]> = out.pixels().map(|p| p.0).collect();
    assert!(colours.len() <= 256, "{}", colours.len());
    // The 8 x 8 blocks keep their mean colours, on average within a level or two: no bands.
    let block_error = |f: &dyn Fn(u32, u32) -> [u8; 3]| {
        let mut total = 0.0f64;
        for (bx, by) in (0..32).flat_map(|bx| (0..8).map(move |by| (bx, by))) {
            for c in 0..3 {
                let (mut a, mut b) = (0.0, 0.0);
                for (x, y) in (0..8).flat_map(|i| (0..8).map(move |j| (8 * bx + i, 8 * by + j))) {
                    a += img.get_pixel(x, y).0[c] as f64;
                    b += f(x, y)[c] as f64;
                }
                total += (a - b).abs() / 64.0;
            }
        }
        total / (32.0 * 8.0 * 3.0)
    };
    let smooth = block_error(&|x, y| {
        let p = out.get_pixel(x, y).0;
        [p[0], p[1], p[2]]
    });
    // The nearest palette colour of each pixel alone makes steps (bands).
    let palette = color_quant::NeuQuant::new(
        1,
        256,
        image::DynamicImage::ImageRgb8(img.clone())
            .to_rgba8()
            .as_raw(),
    );
    let banded = block_error(&|x, y| {
        let p = img.get_pixel(x, y).0;
        let mut q = [p[0], p[1], p[2], 255];
        palette.map_pixel(&mut q);
        [q[0], q[1], q[2]]
    });
    assert!(smooth < 1.2 && banded > 1.5 * smooth, "{smooth} {banded}");
}

/// A drum of radius 1 along y about the origin, its 48 sides and two end caps of triangles.
fn drum() -> Mesh {
    crate::geometry::shapes::Shape::Drum {
        center: DVec3::ZERO,
        axis: DVec3::Y,
        radius: 1.0,
        length: 0.6,
        resolution: 48,
    }
    .mesh(0.0)
}

#[test]
fn a_drum_is_drawn_by_its_rims_and_silhouette_not_the_spokes_of_its_caps() {
    let mesh = drum();
    for view in [View::Iso, View::Front, View::Side] {
        let toward = camera(view).row(2);
        let lines = picture::outline(&mesh, toward);
        // No line reaches the centre of a cap (where the triangles' spokes meet).
        let spoke = |p: DVec3| p.x.abs() < 1e-9 && p.z.abs() < 1e-9;
        assert!(
            lines.iter().all(|(a, b)| !spoke(*a) && !spoke(*b)),
            "{view:?}"
        );
        // The rims, 48 edges each, are all there.
        let on_rim =
            |p: DVec3, y: f64| (p.y - y).abs() < 1e-9 && (p.x.hypot(p.z) - 1.0).abs() < 1e-9;
        for y in [-0.3, 0.3] {
            let rim = lines
                .iter()
                .filter(|(a, b)| on_rim(*a, y) && on_rim(*b, y))
                .count();
            assert_eq!(rim, 48, "{view:?}");
        }
    }
    // Seen from the side (along -x), the silhouette: two seams along the drum, at the top
    // and the bottom; seen along its axis, none (every side is edge-on or hidden).
    let seams = |view| {
        let lines = picture::outline(&mesh, camera(view).row(2));
        lines
            .iter()
            .filter(|(a, b)| (a.y - b.y).abs() > 0.5)
            .count()
    };
    assert_eq!(seams(View::Side), 2);
    // A box's twelve edges, all creases.
    let b = crate::geometry::shapes::Shape::Box {
        min: DVec3::ZERO,
        max: DVec3::ONE,
        open: [false; 6],
    }
    .mesh(0.0);
    assert_eq!(picture::outline(&b, camera(View::Iso).row(2)).len(), 12);
}

#[test]
fn a_drum_about_its_charge_shows_whole_and_a_tall_box_does_not_shrink_its_bed() {
    // Grains in the bottom of the drum: the drum (at most twice as wide) shows whole.
    let mut p = Particles::default();
    for k in 0..40 {
        let a = k as f64 * 0.1;
        let x = DVec3::new(0.6 * a.cos() - 0.3, 0.0, -0.1 - 0.4 * (k % 3) as f64);
        let mut g = one(x, DVec3::ZERO);
        g.radius[0] = 0.1;
        p.push(g.get(0));
    }
    let style = Style {
        view: View::Front,
        ..front(ColorBy::Speed)
    };
    let (lo, hi) = Layout::of(&p, &drum(), &style).bounds();
    assert!(
        lo.x <= -1.0 + 1e-9 && hi.x >= 1.0 - 1e-9 && lo.y <= -1.0 + 1e-9 && hi.y >= 1.0 - 1e-9,
        "{lo} {hi}"
    );
    // A bed 0.2 deep in a box 10 tall: the picture keeps to the bed's height.
    let tall = crate::geometry::shapes::Shape::Box {
        min: DVec3::new(-1.0, -1.0, -1.1),
        max: DVec3::new(1.0, 1.0, 9.0),
        open: [false, false, false, false, false, true],
    }
    .mesh(0.0);
    let (lo, hi) = Layout::of(&p, &tall, &style).bounds();
    assert!(hi.y <= 1e-9 && lo.y >= -1.0 - 1e-9, "{lo} {hi}");
}

#[test]
fn clumps_get_a_colour_each_and_plain_spheres_grey() {
    let c = ColorBy::Clump;
    assert_eq!(c.category(-1.0), PLAIN);
    let colours: std::collections::BTreeSet<[u8; 3]> = (0..20)
        .map(|id| rgb(c.category(id as f64 * 2.0)).0)
        .collect();
    assert!(colours.len() >= 6, "{colours:?}");
    assert!(!colours.contains(&rgb(PLAIN).0));
}
