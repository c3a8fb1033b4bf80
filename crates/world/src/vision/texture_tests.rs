//! Textures as vision sensors see them: a 2 x 2 checker on a 1 m plate seen from above
//! lands in the right quadrants, repeats or clamps, replaces or multiplies the plate's
//! colour, and leaves the depth, mask and colour-coded images as they are untextured.

use std::path::PathBuf;

use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::{VisionStates, handle_vision_sensor, read_mask};
use crate::scene::{LoadOptions, MapFiles, load_scene};
use crate::world::{ShapeTexture, TextureMapping};
use crate::{Handle, Sim};

const RED: [u8; 3] = [255, 0, 0];
const GREEN: [u8; 3] = [0, 255, 0];
const BLUE: [u8; 3] = [0, 0, 255];
const WHITE: [u8; 3] = [255, 255, 255];

/// Side of the sensors' images, pixels.
const SIDE: usize = 40;

/// A 1 x 1 m plate (0.01 m thick, top face at z = 0.005, grey) and, 0.5 m above its top
/// face, looking straight down with x to the image's right and y up, a perspective
/// sensor (90 degrees: it sees exactly the plate), a colour-coded twin and an
/// orthographic one; the checker is texture 0: red, green on the picture's top row,
/// blue, white on its bottom row.
fn scene() -> Sim {
    let sensor = |name: &str, extra: &str| {
        format!(
            "[[object]]\nname = \"{name}\"\nkind = \"vision_sensor\"\nresolution = [{SIDE}, {SIDE}]\n\
             near = 0.01\nfar = 2\nposition = [0, 0, 0.505]\norientation_deg = [0, 180, 0]\n{extra}\n\n"
        )
    };
    let text = String::from("[simulation]\ndt = 0.05\n\n")
        + "[[object]]\nname = \"plate\"\nkind = \"shape\"\nshape = \"box\"\nsize = [1, 1, 0.01]\n\
           color = [0.5, 0.5, 0.5]\n\n"
        + &sensor("eye", "fov_deg = 90")
        + &sensor("coded", "fov_deg = 90\nrender_mode = \"color_coded\"")
        + &sensor("flat", "projection = \"orthographic\"\northo_size = 1");
    let path = PathBuf::from("/texture-test/scene.toml");
    let files = MapFiles::new([(path.clone(), text.into_bytes())]);
    let model = load_scene(&files, &path, &LoadOptions::default()).expect("test scene loads");
    let mut w = Sim::new(&model);
    let checker = [RED, GREEN, BLUE, WHITE]
        .iter()
        .flat_map(|c| [c[0], c[1], c[2], 255])
        .collect();
    assert_eq!(w.world.add_texture("checker", [2, 2], checker), Ok(0));
    w
}

fn find(w: &Sim, name: &str) -> Handle {
    w.world.find(&format!("/{name}"), None, 0).expect(name)
}

/// Puts the checker on the plate, projected on its xy plane with `scaling` (m) and
/// `options` (`sim.setShapeTexture`'s bits).
fn wear(w: &mut Sim, scaling: f64, options: i64) {
    let plate = find(w, "plate");
    let texture = ShapeTexture {
        id: 0,
        mapping: TextureMapping::Plane,
        options,
        uv_scaling: [scaling; 2],
        position: [0.0; 3],
        orientation: [0.0; 3],
        coordinates: None,
    };
    w.world.set_shape_texture(plate, Some(texture)).expect("textured");
}

/// Sensor `name`'s image: RGB per pixel (bottom row first) and depth bits.
fn render(w: &Sim, states: &mut VisionStates, name: &str) -> (Vec<[u8; 3]>, Vec<u32>) {
    let h = find(w, name);
    handle_vision_sensor(&w.world, states, h).expect("renders");
    let img = states.image(h).expect("rendered");
    (
        img.rgb().chunks(3).map(|p| [p[0], p[1], p[2]]).collect(),
        img.depth().iter().map(|d| d.to_bits()).collect(),
    )
}

/// The pixel that sees the plate's point `x`, `y` (m, within the plate): both sensors
/// map the plate onto the whole image.
fn at(rgb: &[[u8; 3]], x: f64, y: f64) -> [u8; 3] {
    let col = ((x + 0.5) * SIDE as f64) as usize;
    let row = ((y + 0.5) * SIDE as f64) as usize;
    rgb[row * SIDE + col]
}

#[test]
fn a_checker_seen_from_above_lands_in_its_quadrants() {
    let mut w = scene();
    let mut states = VisionStates::default();
    let (plain, plain_depth) = render(&w, &mut states, "eye");
    assert!(plain.iter().all(|&p| p == plain[0]), "the untextured plate is one grey");
    // Decal, nearest texel, repeating; the plate is lit fully from above.
    wear(&mut w, 1.0, 1 | 2 | 4 | 8);
    for name in ["eye", "flat"] {
        let (rgb, _) = render(&w, &mut states, name);
        for (x, y, want) in [
            (-0.25, 0.25, RED),
            (0.25, 0.25, GREEN),
            (-0.25, -0.25, BLUE),
            (0.25, -0.25, WHITE),
        ] {
            assert_eq!(at(&rgb, x, y), want, "{name} at ({x}, {y})");
        }
        // Every pixel shows one of the four colours: nothing of the grey is left.
        assert!(rgb.iter().all(|p| [RED, GREEN, BLUE, WHITE].contains(p)), "{name}");
        // The quadrants' borders are where the plate's axes are, to the pixel.
        let quadrant = |col: usize, row: usize| match (col < SIDE / 2, row < SIDE / 2) {
            (true, false) => RED,
            (false, false) => GREEN,
            (true, true) => BLUE,
            (false, true) => WHITE,
        };
        for (i, p) in rgb.iter().enumerate() {
            assert_eq!(*p, quadrant(i % SIDE, i / SIDE), "{name}, pixel {i}");
        }
    }
    // The depth image does not change.
    assert_eq!(render(&w, &mut states, "eye").1, plain_depth);

    // Not decal: the texel multiplies the plate's grey.
    wear(&mut w, 1.0, 1 | 4 | 8);
    let (rgb, _) = render(&w, &mut states, "eye");
    assert_eq!(at(&rgb, 0.25, -0.25), [128; 3]);
    assert_eq!(at(&rgb, -0.25, 0.25), [128, 0, 0]);
}

#[test]
fn coordinates_past_the_texture_repeat_or_clamp() {
    let mut w = scene();
    let mut states = VisionStates::default();
    // The texture 0.5 m wide: the plate's middle half shows it once; outside it u and v
    // run to -0.5 and 1.5.
    wear(&mut w, 0.5, 1 | 2 | 4 | 8);
    let (repeated, _) = render(&w, &mut states, "eye");
    // Repeating: near the corner (-0.4, -0.4), u = v = 0.7, the picture's top right.
    assert_eq!(at(&repeated, -0.4, -0.4), GREEN);
    assert_eq!(at(&repeated, 0.4, 0.4), BLUE);
    assert_eq!(at(&repeated, -0.1, 0.1), RED);
    // Clamped: the edge texels go on.
    wear(&mut w, 0.5, 1 | 2);
    let (clamped, _) = render(&w, &mut states, "eye");
    assert_eq!(at(&clamped, -0.4, -0.4), BLUE);
    assert_eq!(at(&clamped, 0.4, 0.4), GREEN);
    assert_eq!(at(&clamped, -0.1, 0.1), RED);
    // Repeating along u only: clamped along v.
    wear(&mut w, 0.5, 1 | 2 | 4);
    let (mixed, _) = render(&w, &mut states, "eye");
    assert_eq!(at(&mixed, -0.4, -0.4), WHITE);
}

#[test]
fn bilinear_sampling_blends_across_texel_borders() {
    let mut w = scene();
    let mut states = VisionStates::default();
    wear(&mut w, 1.0, 2 | 4 | 8);
    let (rgb, _) = render(&w, &mut states, "flat");
    // Near a texel's centre about its colour; at the border between blue and white,
    // halfway between them.
    let [r, g, b] = at(&rgb, -0.25, -0.25);
    assert!(r < 20 && g < 20 && b > 240, "{:?}", [r, g, b]);
    let [r, g, b] = at(&rgb, 0.0, -0.25);
    assert!(
        (100..160).contains(&r) && (100..160).contains(&g) && b > 240,
        "{:?}",
        [r, g, b]
    );
}

#[test]
fn textures_leave_masks_and_colour_coded_images_alone() {
    let mut w = scene();
    let mut states = VisionStates::default();
    let eye = find(&w, "eye");
    let mask = |w: &Sim, states: &mut VisionStates| {
        read_mask(&w.world, states, eye).expect("mask");
        states
            .image(eye)
            .and_then(super::SensorImage::mask)
            .map(<[i32]>::to_vec)
    };
    let (plain_mask, plain_coded) = (mask(&w, &mut states), render(&w, &mut states, "coded"));
    let plain = render(&w, &mut states, "eye");
    wear(&mut w, 1.0, 1 | 2 | 4 | 8);
    let mut textured = VisionStates::default();
    assert_eq!(mask(&w, &mut textured), plain_mask);
    assert_eq!(render(&w, &mut textured, "coded"), plain_coded);
    // The colours change; taking the texture off gives the plain image back.
    assert_ne!(render(&w, &mut textured, "eye").0, plain.0);
    w.world.set_shape_texture(find(&w, "plate"), None).expect("untextured");
    assert_eq!(render(&w, &mut textured, "eye"), plain);
}

#[test]
fn a_tilted_view_interpolates_in_perspective() {
    // Seen at a slant, the checker's vertical border (x = 0 on the plate) stays a
    // straight line through the image's centre column; interpolated affinely across the
    // plate's two triangles it would bend away from it.
    let mut w = scene();
    let eye = find(&w, "eye");
    // Looking down at the plate's centre from behind its near edge: turned over about y
    // (x to the image's right, as above), then tilted about x.
    let tilt = (0.45f64).atan2(0.4);
    let rotation = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), tilt)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI);
    let pose = crate::math::Pose::from_parts(Translation3::new(0.0, -0.45, 0.4), rotation);
    w.world.set_world_pose(eye, pose).expect("pose");
    wear(&mut w, 1.0, 1 | 2 | 4 | 8);
    let mut states = VisionStates::default();
    let (rgb, _) = render(&w, &mut states, "eye");
    // Lit at a slant, the colours are darker: red and blue are those without green,
    // the background is black.
    let mut seen = 0;
    for (i, p) in rgb.iter().enumerate() {
        if *p != [0; 3] {
            let left = i % SIDE < SIDE / 2;
            assert_eq!(p[1] == 0, left, "pixel {i} (row {}): {p:?}", i / SIDE);
            seen += 1;
        }
    }
    assert!(seen > SIDE * SIDE / 2, "the plate covers {seen} pixels");
}
