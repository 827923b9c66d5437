# Synthetic lat-long maps (frf's convention, docs/conventions.md) for judging hard light:
# broad overhead lobes, suns of several diameters, windows (each over a sky of radiance 1
# and a ground of 0.3, the source carrying a share of all the light), and overcast skies
# whose zenith glows with a hot spot in it. Needs numpy and OpenEXR.
#   python3 scripts/hard-light-maps.py OUT_DIR     (then scripts/hard-light-eval.sh)
import numpy as np, OpenEXR, math, sys, os
OUT = sys.argv[1] if len(sys.argv) > 1 else "maps"
os.makedirs(OUT, exist_ok=True)
W, H = 1024, 512
x = np.arange(W) + 0.5; y = np.arange(H) + 0.5
phi = (2 * x / W - 1) * math.pi; theta = y / H * math.pi
T, P = np.meshgrid(theta, phi, indexing='ij')
D = np.stack([np.sin(T) * np.sin(P), np.cos(T), -np.sin(T) * np.cos(P)], -1)
dom = (2 * math.pi / W) * (math.pi / H) * np.sin(T)
def direction(az, el):
    az, el = math.radians(az), math.radians(el)
    return np.array([math.sin(az) * math.cos(el), math.sin(el), math.cos(az) * math.cos(el)])
def base():
    return np.where(D[..., 1] > 0, 1.0, 0.3)
def write(name, img):
    rgb = np.repeat(img[..., None], 3, -1).astype(np.float32)
    with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}, {"RGB": rgb}) as f:
        f.write(f"{OUT}/{name}.exr")
def finish(name, bg, src, share):
    # scale the source to carry `share` of the total light
    lb = (bg * dom).sum(); ls = (src * dom).sum()
    k = share / (1 - share) * lb / ls
    img = bg + k * src
    write(name, img)
    print(name, "peak/mean", float(img.max() / ((img * dom).sum() / (4 * math.pi))))
def lobe(az, el, sigma):
    a = np.degrees(np.arccos(np.clip(D @ direction(az, el), -1, 1)))
    return np.exp(-0.5 * (a / sigma) ** 2)
def disc(az, el, diam):
    a = np.degrees(np.arccos(np.clip(D @ direction(az, el), -1, 1)))
    return (a <= diam / 2).astype(float) + 0.0
def window(az, el, w, h):
    d = direction(az, el)
    az_t = np.degrees(np.arctan2(D[..., 0], D[..., 2])); el_t = np.degrees(np.arcsin(np.clip(D[..., 1], -1, 1)))
    daz = (az_t - az + 180) % 360 - 180
    return ((np.abs(daz) <= w / 2) & (np.abs(el_t - el) <= h / 2)).astype(float)
for name, src, share in [
    ("lobe_zenith_s4", lobe(0, 90, 4), 0.5), ("lobe_zenith_s7", lobe(0, 90, 7), 0.6),
    ("lobe_70_s5", lobe(120, 70, 5), 0.5), ("lobe_60_s10", lobe(200, 60, 10), 0.7),
    ("sun_0p5_40", disc(60, 40, 0.53), 0.5), ("sun_2_30", disc(250, 30, 2), 0.5),
    ("sun_5_50", disc(30, 50, 5), 0.5), ("sun_5_25", disc(150, 25, 5), 0.4),
    ("window_20", window(90, 20, 10, 20), 0.5), ("window_35", window(300, 35, 15, 25), 0.6),
]:
    finish(name, base(), src, share)
# Overcast with a bright zenith: a CIE-like overcast sky, a broad zenith glow and a
# small hot spot in it, so that the brightest texel passes the sun test while the light
# above a tenth of it spans tens of degrees.
def overcast():
    el = np.clip(D[..., 1], 0, 1)
    return np.where(D[..., 1] > 0, (1 + 2 * el) / 3, 0.2)
for name, bsig, bshare, hsig, hshare, az, el in [
    ("overcast_hot_a", 15, 0.45, 1.5, 0.06, 0, 90), ("overcast_hot_b", 20, 0.5, 2.0, 0.08, 40, 75),
    ("overcast_hot_c", 12, 0.40, 1.0, 0.04, 200, 80),
]:
    bg = overcast()
    lb = (bg * dom).sum()
    glow = lobe(az, el, bsig); hot = lobe(az, el, hsig)
    # shares of the total: glow bshare, hot hshare
    total = lb / (1 - bshare - hshare)
    img = bg + glow * (bshare * total / (glow * dom).sum()) + hot * (hshare * total / (hot * dom).sum())
    write(name, img)
    thr = img.max() * 0.1
    print(name, "peak/mean", float(img.max() / ((img * dom).sum() / (4 * math.pi))), "area >=10% peak (sr)", float(dom[img >= thr].sum()))
# Bright ground: a sun and a sky over a ground sending up a large share of the light (a
# savanna's dry grass), the ground a little brighter toward the sun's side.
for name, share_below, az, el in [("bright_ground_a", 0.47, 60, 35), ("bright_ground_b", 0.40, 220, 50)]:
    sky = np.where(D[..., 1] > 0, 1.0, 0.0)
    sun = disc(az, el, 0.53)
    side = np.clip(D @ direction(az, 0) * 0.5 + 1.0, 0.5, 1.5)
    ground = np.where(D[..., 1] <= 0, side, 0.0)
    upper = sky + sun * (0.5 * (sky * dom).sum() / (sun * dom).sum() * 2.0)
    lu = (upper * dom).sum(); lg = (ground * dom).sum()
    img = upper + ground * (share_below / (1 - share_below) * lu / lg)
    write(name, img)
    below = float((img * dom)[D[..., 1] <= 0].sum() / (img * dom).sum())
    print(name, "share of the light from below", round(below, 3))
# Light from below alone: a soft sky over a bright ground (no sun), the ground brighter
# toward one side, and a ground with a small sunlit patch (a bright slab beside the walker).
for name, share_below, patch in [("ground_soft", 0.47, None), ("ground_patch", 0.45, (100, -40, 15))]:
    sky = np.where(D[..., 1] > 0, 1.0, 0.0)
    side = np.clip(D @ direction(30, 0) * 0.5 + 1.0, 0.5, 1.5)
    ground = np.where(D[..., 1] <= 0, side, 0.0)
    if patch is not None:
        ground = ground + 8.0 * np.where(D[..., 1] <= 0, lobe(*patch), 0.0)
    lu = (sky * dom).sum(); lg = (ground * dom).sum()
    img = sky + ground * (share_below / (1 - share_below) * lu / lg)
    write(name, img)
    below = float((img * dom)[D[..., 1] <= 0].sum() / (img * dom).sum())
    print(name, "share of the light from below", round(below, 3))
