# Experiment (issue 24): is flow-based interpolation in time, in the novel view, worth it?
# For each half-way frame: nearest pose, a cross-fade, and a flow morph of the two
# neighbouring poses' renders (flows computed on the renders), scored against the truth.
import sys, numpy as np, OpenEXR

def exr(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGBA" in ch:
            return np.asarray(ch["RGBA"].pixels, dtype=np.float64)
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGBA"], -1)

def flo(path):
    b = open(path, "rb").read()
    w, h = np.frombuffer(b[4:12], dtype=np.int32)
    f = np.frombuffer(b[12:], dtype=np.float32).reshape(h, w, 2).astype(np.float64)
    f[~np.isfinite(f)] = 0
    f[np.abs(f) > 1e9] = 0
    return f

def sample(img, x, y):
    h, w = img.shape[:2]
    x = np.clip(x, 0, w - 1); y = np.clip(y, 0, h - 1)
    x0 = np.floor(x).astype(int); y0 = np.floor(y).astype(int)
    x1 = np.minimum(x0 + 1, w - 1); y1 = np.minimum(y0 + 1, h - 1)
    fx = (x - x0)[..., None]; fy = (y - y0)[..., None]
    return (img[y0, x0] * (1 - fx) * (1 - fy) + img[y0, x1] * fx * (1 - fy)
            + img[y1, x0] * (1 - fx) * fy + img[y1, x1] * fx * fy)

def psnr(truth, test):
    mask = (truth[..., 3] > 0.01) | (test[..., 3] > 0.01)
    peak = truth[..., :3][mask].max()
    mse = ((truth[..., :4] - test[..., :4])[mask] ** 2).mean()
    return 10 * np.log10(peak ** 2 / mse)

d = sys.argv[1]
rows = []
for i in [1, 3, 5, 7, 9]:
    a = exr(f"{d}/frame_{i-1:04d}.exr"); b = exr(f"{d}/frame_{i+1:04d}.exr")
    t = exr(f"{d}/truth_{i}.exr")
    f = flo(f"{d}/f_{i}.flo"); g = flo(f"{d}/g_{i}.flo")
    h, w = a.shape[:2]
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64)
    s = 0.5
    # Backward warps with the flow taken at the target pixel (smooth-flow approximation).
    wa = sample(a, xs - s * f[..., 0], ys - s * f[..., 1])
    wb = sample(b, xs - (1 - s) * g[..., 0], ys - (1 - s) * g[..., 1])
    morph = (1 - s) * wa + s * wb
    rows.append((psnr(t, a), psnr(t, 0.5 * (a + b)), psnr(t, morph)))
    print(f"frame {i}: nearest {rows[-1][0]:.2f} dB, cross-fade {rows[-1][1]:.2f} dB, flow morph {rows[-1][2]:.2f} dB")
m = np.mean(rows, 0)
print(f"mean: nearest {m[0]:.2f} dB, cross-fade {m[1]:.2f} dB, flow morph {m[2]:.2f} dB")
even = [i for i in [2, 4, 6] if __import__("os").path.exists(f"{d}/truth_{i}.exr")]
if even:
    at = [psnr(exr(f"{d}/truth_{i}.exr"), exr(f"{d}/frame_{i:04d}.exr")) for i in even]
    print(f"at pose instants (frames {even}): {np.mean(at):.2f} dB")
