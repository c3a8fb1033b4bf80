"""The viewer's viewpoint menu (issue 28: CoppeliaSim cameras as viewer viewpoints): a
scene with a camera over a red box, the real page in headless chromium, the camera moved
from outside through the ZMQ remote API.

Run with the others by ``bash tools/browser-test.sh``, or alone with
``bash tools/browser-test.sh -k scene_camera``.
"""

from __future__ import annotations

import pytest
from playwright.sync_api import sync_playwright

from viewer_util import Gantry, launch_chromium, wait_for

# A red box at x = 2 and a blue one at x = -2 on a floor; the camera 1.5 m above the red
# one, looking straight down (its +Z is the world's -Z), with a 40 degree view angle.
# The orbit view frames both boxes, so its centre is the floor between them.
SCENE = """
[floor]
size = [8, 8]

[[object]]
name = "red"
kind = "shape"
shape = "box"
size = [0.6, 0.6, 0.2]
position = [2, 0, 0.1]
color = [1, 0, 0]

[[object]]
name = "blue"
kind = "shape"
shape = "box"
size = [0.6, 0.6, 0.2]
position = [-2, 0, 0.1]
color = [0, 0, 1]

[[object]]
name = "overhead"
kind = "camera"
position = [2, 0, 1.5]
orientation_deg = [180, 0, 0]
fov_deg = 40
"""

CENTRE_COLOUR = """async () => {
    const img = new Image();
    await new Promise((ok, bad) => { img.onload = ok; img.onerror = bad; img.src = gantry.capture(); });
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(img, 0, 0);
    return Array.from(ctx.getImageData(img.width >> 1, img.height >> 1, 1, 1).data.slice(0, 3));
}"""


@pytest.fixture(scope="module")
def gantry(tmp_path_factory):
    scene = tmp_path_factory.mktemp("cameras") / "cameras.toml"
    scene.write_text(SCENE)
    g = Gantry(extra=[str(scene)])
    yield g
    g.close()


def centre(page) -> list[int]:
    return page.evaluate(CENTRE_COLOUR)


def redder(c):
    return c[0] > 2 * max(c[1], c[2]) + 20


def bluer(c):
    return c[2] > 2 * max(c[0], c[1]) + 20


def test_the_view_goes_through_a_scene_camera_and_follows_it(gantry):
    with sync_playwright() as p:
        browser = launch_chromium(p)
        page = browser.new_page(viewport={"width": 1000, "height": 700})
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(gantry.url)
        # Nothing moves in this scene: the first frame (every pose) is all that comes.
        page.wait_for_function("window.gantry && gantry.objects.length > 0 && gantry.framesRendered > 0 "
                               "&& gantry.frameMessages > 0", timeout=20_000)
        menu = page.locator("#viewpoint")
        assert menu.is_visible()
        labels = menu.locator("option").all_inner_texts()
        assert labels == ["orbit view", "camera /overhead"], labels
        orbit = centre(page)
        assert not redder(orbit) and not bluer(orbit), orbit

        menu.select_option(label="camera /overhead")
        wait_for(lambda: redder(centre(page)), what="the red box under the camera")

        # The camera moves (a client sets its position): the view follows it.
        client = gantry.zmq_client()
        sim = client.require("sim")
        cam = sim.getObject("/overhead")
        sim.setObjectPosition(cam, -1, [-2, 0, 1.5])
        wait_for(lambda: bluer(centre(page)), what="the blue box under the moved camera")

        # The wheel returns to the orbit view.
        page.mouse.move(500, 350)
        page.mouse.wheel(0, 100)
        wait_for(lambda: menu.input_value() == "", what="the orbit view back")
        assert not errors, f"JavaScript errors on the page: {errors}"
        browser.close()
