#!/usr/bin/env python3
"""The colour-conversion study of docs/colour.md: how far each way of turning
the renderer's three wavelengths (680/550/440 nm) into Rec.709 is from the
48-bin spectral mode, texel by texel, as CIE 1976 u'v' distances.

    /usr/bin/python3 tests/colour/conversion_options.py --skybake build/skybake --out /tmp/colour_study

For each sun elevation it bakes the default style twice as float32 latlongs of
64 x 32 (three wavelengths in spectral units, i.e. the raw radiance, and 48
bins integrated with the CIE 1931 functions), then converts the raw radiance
with each option and compares:
  sky        Bruneton 2017's SKY_SPECTRAL_RADIANCE_TO_LUMINANCE for every texel
  sun        Bruneton 2017's SUN_SPECTRAL_RADIANCE_TO_LUMINANCE for every texel
  lin3x3     one 3x3 matrix from a quadratic (Lagrange) spectrum through the samples
  logquad    per texel, the log of the spectrum quadratic through the samples
  oracle3x3  the best 3x3 matrix for the frame (least squares on the reference
             itself): the floor of any per-frame matrix
and, with --converted DIR (a bake of the current default conversion, same
schedule), skybake's own per-frame conversion (colour_conversion.h).
Needs numpy (Debian's python3-numpy) and oiiotool (openimageio-tools).
"""
import argparse, json, os, re, subprocess, sys
import numpy as np

ELEVATIONS = [90, 45, 20, 10, 5, 2, -3, -6, -10]
REC709_TO_XYZ = np.array([[0.4124564, 0.3575761, 0.1804375], [0.2126729, 0.7151522, 0.0721750],
                          [0.0193339, 0.1191920, 0.9503041]])
SKY_K = np.array([114974.916437, 71305.954816, 65310.548555])
SUN_K = np.array([98242.79, 69954.40, 66475.01])
SAMPLES_NM = np.array([680.0, 550.0, 440.0])


def tables(root):
    src = open(os.path.join(root, 'bake/model/spectral_tables.cc')).read()
    atm = np.array([[float(v) for v in m.groups()] for m in re.finditer(
        r'\{(\d+\.0), ([\d.e+-]+), ([\d.e+-]+), ([\d.e+-]+), ([\d.e+-]+), ([\d.e+-]+)\}', src)])
    cie = np.array([[float(v) for v in m.groups()] for m in re.finditer(
        r'\{(\d+\.0), ([\d.e+-]+), ([\d.e+-]+), ([\d.e+-]+)\},', src)])
    lam, solar = atm[:, 0], atm[:, 1]
    weights = np.zeros((len(lam), 3))  # 683 x the CIE functions' integral over each 10 nm bin
    for k, l in enumerate(lam):
        xs = np.linspace(l - 5, l + 5, 11)
        f = np.array([np.interp(xs, cie[:, 0], cie[:, c], left=0, right=0) for c in (1, 2, 3)])
        weights[k] = 683.0 * np.trapz(f, xs, axis=1)
    return lam, solar, weights


def read_exr(path):
    out = subprocess.run(['oiiotool', '--dumpdata', path], check=True, capture_output=True, text=True).stdout
    head = re.search(r':\s+(\d+) x\s+(\d+)', out)
    w, h = int(head.group(1)), int(head.group(2))
    px = [[float(v) for v in line.split(':', 1)[1].split()[:3]] for line in out.splitlines() if 'Pixel (' in line]
    return np.array(px).reshape(h, w, 3)


def uv(xyz):
    d = xyz[:, 0] + 15 * xyz[:, 1] + 3 * xyz[:, 2]
    return np.stack([4 * xyz[:, 0] / d, 9 * xyz[:, 1] / d], 1)


def lagrange(x):
    basis = np.zeros((len(x), 3))
    for i in range(3):
        b = np.ones(len(x))
        for j in range(3):
            if j != i:
                b *= (x - SAMPLES_NM[j]) / (SAMPLES_NM[i] - SAMPLES_NM[j])
        basis[:, i] = b
    return basis


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--skybake', default='build/skybake')
    p.add_argument('--out', default='/tmp/skybake_colour_study')
    p.add_argument('--converted', help='bake the default conversion too and report it', action='store_true')
    a = p.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    lam, solar, weights = tables(root)
    e3 = np.array([np.interp(l, lam, solar) for l in SAMPLES_NM])
    lin3x3 = (weights.T * solar) @ lagrange(lam) / e3
    common = ['--size', '32', '-q', '--set', 'output.pixel_type="float"', '--set', 'output.faces=false',
              '--set', 'output.cube_strip=false', '--set', 'output.preview=false', '--set', 'gltf.enabled=false']
    runs = {'raw': ['--set', 'output.units="spectral"'], 'ref': ['--set', 'quality.wavelengths=48']}
    if a.converted:
        runs['skybake'] = []
    print('sun   option      u\'v\' mean  worst   (upper hemisphere, texels above 1e-6 of the brightest)')
    for e in ELEVATIONS:
        img = {}
        for name, extra in runs.items():
            out = os.path.join(a.out, f'{name}_{e}')
            subprocess.run([a.skybake, 'bake', os.path.join(root, 'configs/default.toml'), '--out', out, '--force',
                            '--set', f'sun.elevation_deg={e}'] + common + extra, check=True, capture_output=True)
            img[name] = read_exr(os.path.join(out, 'sky_latlong.exr'))
        h = img['raw'].shape[0]
        raw = img['raw'][:h // 2].reshape(-1, 3)
        ref = img['ref'][:h // 2].reshape(-1, 3) @ REC709_TO_XYZ.T
        keep = ref[:, 1] > 1e-6 * ref[:, 1].max()
        raw, ref = raw[keep], ref[keep]
        w = 1.0 / ref[:, 1]
        oracle, *_ = np.linalg.lstsq(raw * w[:, None], ref * w[:, None], rcond=None)
        t = np.log(np.maximum(raw / e3, 1e-30))
        options = {
            'sky': (raw * SKY_K) @ REC709_TO_XYZ.T,
            'sun': (raw * SUN_K) @ REC709_TO_XYZ.T,
            'lin3x3': raw @ lin3x3.T,
            'logquad': (np.exp(t @ lagrange(lam).T) * solar) @ weights,
            'oracle3x3': raw @ oracle,
        }
        if 'skybake' in img:
            options['skybake'] = img['skybake'][:h // 2].reshape(-1, 3)[keep] @ REC709_TO_XYZ.T
        for name, xyz in options.items():
            d = np.linalg.norm(uv(xyz) - uv(ref), axis=1)
            print(f'{e:4d}  {name:10s}  {d.mean():.4f}     {d.max():.4f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
