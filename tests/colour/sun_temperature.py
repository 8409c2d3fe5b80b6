#!/usr/bin/env python3
"""The Sun's colour temperature against the world (docs/colour_sun_temperature.md).

    /usr/bin/python3 tests/colour/sun_temperature.py --skybake build/skybake --out /tmp/skybake_cct

1. Bakes configs/default.toml at fixed sun elevations (5 ... 90 deg, azimuth
   135) three ways: the 48-bin spectral mode (the reference), the default three
   wavelengths (the per-path conversion), and raw spectral units (680/550/440
   nm) times Bruneton 2017's sky factors, i.e. the previous release's colour.
   It reads the Sun's light from each frame's manifest (frames[i].sun.irradiance,
   linear Rec.709; raw radiance in spectral units) and prints its correlated
   colour temperature (CCT) and Duv. The same is done with the aerosol of the
   Kider 2014 day (AERONET Egbert, 2013-05-27) in place of the default's.
2. With --g173 FILE (ASTM G173-03 as CSV: wavelength, extraterrestrial,
   global, direct; e.g. pvlib's pvlib/data/ASTMG173.csv) it adds the CCT of that
   standard's direct-normal spectrum (a SMARTS 2.9.2 model at air mass 1.5,
   sun elevation 41.81 deg) and of its extraterrestrial spectrum.
3. Kider 2014 (../shared/groundtruth/kider2014): the measured sky samples
   within 20 deg of the Sun and the whole 81-sample sky of every capture
   (CIE XYZ from photometric.csv, equal-area samples summed), against the same
   directions read from latlong bakes of every capture's sun position.

CCT: the definition itself, the Planckian radiator nearest in the CIE 1960
(u, v) diagram. The locus is integrated from Planck's law (c2 = 1.4388e-2 m K)
against the CIE 1931 2-degree functions (the 5 nm table of the ground truth,
linear at 1 nm) for 1000 K .. 1e6 K at 0.025 % steps of T, the nearest point is
refined by a parabola through its neighbours (as Ohno 2014's parabolic
solution; error well under 1 K), and Duv is the signed distance to the locus
at that T (positive above it, Ohno 2014; ANSI C78.377). The script checks
itself on CIE illuminants A and D65 (2856 K, 6504 K) and prints how far
McCamy 1992's cubic is from it on the Planckian locus (it is not used).
Needs numpy and oiiotool (openimageio-tools).
"""
import argparse, csv, json, math, os, re, subprocess, sys
import numpy as np

from conversion_options import read_exr  # oiiotool --dumpdata -> (height, width, 3)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
REC709_TO_XYZ = np.array([[0.4124564, 0.3575761, 0.1804375], [0.2126729, 0.7151522, 0.0721750],
                          [0.0193339, 0.1191920, 0.9503041]])
SKY_K = np.array([114974.916437, 71305.954816, 65310.548555])  # Bruneton 2017 SKY_SPECTRAL_RADIANCE_TO_LUMINANCE
ELEVATIONS = [5, 10, 15, 20, 30, 35, 45, 60, 90]
NEAR_SUN_DEG = 20.0
# The Kider 2014 day's aerosol (README of ../shared/groundtruth: AERONET Egbert, AOD(440 nm) 0.114-0.128,
# Angstrom exponent 0.86-1.17): AOD(440) 0.12, exponent 1.0, over the style's 1.2 km scale height, single
# scattering albedo 0.9 as the default style's. Values at [680, 550, 440] nm, per km.
DAY_AOD = [0.12 * (lam / 440.0) ** -1.0 for lam in (680.0, 550.0, 440.0)]
TRIPLET = '[{:.5f}, {:.5f}, {:.5f}]'
DAY_MIE = ['--set', 'atmosphere.mie.extinction_per_km=' + TRIPLET.format(*[t / 1.2 for t in DAY_AOD]),
           '--set', 'atmosphere.mie.scattering_per_km=' + TRIPLET.format(*[0.9 * t / 1.2 for t in DAY_AOD])]
# ASTM G173-03's atmosphere (SMARTS 2.9.2): AOD 0.084 at 500 nm, Angstrom exponent about 1.2 (rural aerosol),
# ozone 0.3438 atm-cm (the style's tent holds 300 DU); air mass 1.5 = sun elevation 41.81 deg.
G173_AOD = [0.084 * (lam / 500.0) ** -1.2 for lam in (680.0, 550.0, 440.0)]
G173_ATM = ['--set', 'atmosphere.mie.extinction_per_km=' + TRIPLET.format(*[t / 1.2 for t in G173_AOD]),
            '--set', 'atmosphere.mie.scattering_per_km=' + TRIPLET.format(*[0.9 * t / 1.2 for t in G173_AOD]),
            '--set', 'atmosphere.ozone.absorption_per_km=[{:.4e}, {:.4e}, {:.4e}]'.format(
                *[k * 343.8 / 300.0 for k in (0.650e-3, 1.881e-3, 0.085e-3)])]
G173_ELEVATION = 41.81
# Abbot's noon sunlight at Washington D.C. (38.9 deg N), half at each solstice: the noon sun at 90 - |38.9 - 23.44|
# and 90 - (38.9 + 23.44) deg.
ABBOT_ELEVATIONS = [74.54, 27.66]
COMMON = ['-q', '--set', 'output.pixel_type="float"', '--set', 'output.faces=false', '--set', 'output.cube_strip=false',
          '--set', 'output.preview=false', '--set', 'gltf.enabled=false']
MODES = {  # name: extra options
    'spectral48': ['--set', 'quality.wavelengths=48'],
    'rgb': [],
    'raw': ['--set', 'output.units="spectral"'],
}


class Planck:
    """CCT and Duv from chromaticity, by the nearest point of the Planckian locus in CIE 1960 (u, v)."""
    C2 = 1.4388e-2  # m K (CIE 15)

    def __init__(self, cmf_csv):
        rows = [r for r in csv.reader(open(cmf_csv)) if r and not r[0].startswith('#')][1:]
        t = np.array([[float(v) for v in r[:4]] for r in rows])
        self.lam = np.arange(t[0, 0], t[-1, 0] + 0.5, 1.0)
        self.cmf = np.stack([np.interp(self.lam, t[:, 0], t[:, c]) for c in (1, 2, 3)], 1)
        self.log_t = np.linspace(math.log(1000.0), math.log(1.0e6), 55265)  # 0.025 % steps
        self.uv_table = self.locus_uv(np.exp(self.log_t))

    def locus_uv(self, temps):
        temps = np.atleast_1d(temps)
        lam_m = self.lam * 1e-9
        spd = lam_m ** -5 / np.expm1(self.C2 / np.outer(temps, lam_m))
        return uv60(spd @ self.cmf)

    def cct_duv(self, xyz):
        u, v = uv60(np.asarray(xyz, float)[None, :])[0]
        d2 = (self.uv_table[:, 0] - u) ** 2 + (self.uv_table[:, 1] - v) ** 2
        i = int(np.clip(np.argmin(d2), 1, len(d2) - 2))
        a, b, c = d2[i - 1], d2[i], d2[i + 1]
        den = a - 2 * b + c
        f = 0.5 * (a - c) / den if den > 0 else 0.0
        t = math.exp(self.log_t[i] + f * (self.log_t[1] - self.log_t[0]))
        ul, vl = self.locus_uv(t)[0]
        return t, math.copysign(math.hypot(u - ul, v - vl), v - vl)


def uv60(xyz):
    xyz = np.atleast_2d(xyz)
    d = xyz[:, 0] + 15 * xyz[:, 1] + 3 * xyz[:, 2]
    return np.stack([4 * xyz[:, 0] / d, 6 * xyz[:, 1] / d], 1)


def uv76(xyz):
    u, v = uv60(xyz)[0]
    return np.array([u, 1.5 * v])


def xy_to_xyz(x, y):
    return np.array([x / y, 1.0, (1 - x - y) / y])


def mccamy(xyz):
    x, y = xyz[0] / xyz.sum(), xyz[1] / xyz.sum()
    n = (x - 0.3320) / (0.1858 - y)
    return 449 * n ** 3 + 3525 * n ** 2 + 6823.3 * n + 5520.33


def self_check(p):
    a = p.cct_duv(xy_to_xyz(0.44757, 0.40745))
    d65 = p.cct_duv(xy_to_xyz(0.31271, 0.32902))
    worst, worst_mccamy = 0.0, 0.0
    for t in np.linspace(2000, 10000, 161):
        lam_m = p.lam * 1e-9
        xyz = (lam_m ** -5 / np.expm1(p.C2 / (lam_m * t))) @ p.cmf
        worst = max(worst, abs(p.cct_duv(xyz)[0] - t))
        worst_mccamy = max(worst_mccamy, abs(mccamy(xyz) - t))
    print(f'# CCT check: illuminant A {a[0]:.0f} K (Duv {a[1]:+.4f}), D65 {d65[0]:.0f} K (Duv {d65[1]:+.4f}); '
          f'Planckian 2000-10000 K recovered within {worst:.2f} K; McCamy 1992 is off by up to {worst_mccamy:.0f} K '
          f'there (not used)')


def direction(elevation_deg, azimuth_deg):
    """Unit vector, azimuth clockwise from North; North = -Z, East = +X, up = +Y (configs/default.toml)."""
    e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
    return np.array([math.sin(a) * math.cos(e), math.sin(e), -math.cos(a) * math.cos(e)])


def sample_latlong(img, d):
    """Bilinear read of an OpenEXR latlong (Imf::LatLongMap, shaders/envmap.glsl) in direction d."""
    h, w, _ = img.shape
    lon, lat = math.atan2(d[0], d[2]), math.asin(max(-1.0, min(1.0, d[1])))
    x, y = (0.5 - lon / (2 * math.pi)) * (w - 1), (0.5 - lat / math.pi) * (h - 1)
    x0, y0 = min(int(x), w - 2), min(int(y), h - 2)
    fx, fy = x - x0, y - y0
    return ((1 - fx) * (1 - fy) * img[y0, x0] + fx * (1 - fy) * img[y0, x0 + 1] + (1 - fx) * fy * img[y0 + 1, x0] +
            fx * fy * img[y0 + 1, x0 + 1])


def bake(a, out, schedule, size, extra):
    cmd = [a.skybake, 'bake', os.path.join(ROOT, 'configs/default.toml'), '--schedule', schedule, '--size', str(size),
           '--out', out, '--force'] + COMMON + extra
    if not a.reuse or not os.path.exists(os.path.join(out, 'manifest.json')):
        subprocess.run(cmd, check=True, capture_output=True)
    return json.load(open(os.path.join(out, 'manifest.json')))


def write_schedule(path, frames):
    with open(path, 'w') as f:
        f.write('[schedule]\n')
        for e, az in frames:
            f.write(f'[[schedule.frames]]\nelevation_deg = {e:.4f}\nazimuth_deg = {az:.4f}\n')
    return path


def sun_xyz(manifest, frame, mode):
    rgb = np.array(manifest['frames'][frame]['sun']['irradiance'], float)
    if mode == 'raw':
        rgb = rgb * SKY_K
    return REC709_TO_XYZ @ rgb


def fmt(td):
    return f'{td[0]:6.0f} K {td[1]:+.4f}'


def sun_table(a, p):
    sched = write_schedule(os.path.join(a.out, 'elevations.toml'), [(e, 135.0) for e in ELEVATIONS])
    res, xyz = {}, {}
    for aerosol, mie in (('default', []), ('day', DAY_MIE)):
        for mode, extra in MODES.items():
            m = bake(a, os.path.join(a.out, f'sun_{aerosol}_{mode}'), sched, 16, extra + mie)
            xyz[(aerosol, mode)] = [sun_xyz(m, f, mode) for f in range(len(ELEVATIONS))]
            res[(aerosol, mode)] = [p.cct_duv(v) for v in xyz[(aerosol, mode)]]
    atm = atmosphere_table()
    res['beer_lambert'] = [p.cct_duv(beer_lambert_sun(p, atm, e)) for e in ELEVATIONS]
    print('\n## The Sun (direct beam, manifest frames[i].sun.irradiance): CCT and Duv\n')
    print('| sun elevation | 48-bin spectral (reference) | three wavelengths (default) '
          '| previous release (sky factors) | 48-bin, Kider-day aerosol | three wavelengths, Kider-day aerosol '
          '| check: Beer-Lambert, 48 bins |')
    print('| ---: | ---: | ---: | ---: | ---: | ---: | ---: |')
    for i, e in enumerate(ELEVATIONS):
        cells = [res[k][i] for k in (('default', 'spectral48'), ('default', 'rgb'), ('default', 'raw'),
                                     ('day', 'spectral48'), ('day', 'rgb'), 'beer_lambert')]
        print(f'| {e} deg | ' + ' | '.join(f'{t:.0f} K ({d:+.4f})' for t, d in cells) + ' |')
    for mode, label in (('rgb', 'three wavelengths'), ('raw', 'previous release')):
        print(f'\nu\'v\' distance of the {label} to the 48-bin sun: ' + ', '.join(
            f'{e} deg {np.linalg.norm(uv76(xyz[("default", mode)][i]) - uv76(xyz[("default", "spectral48")][i])):.4f}'
            for i, e in enumerate(ELEVATIONS)))
    return res


def g173_table(a, p):
    rows = [r for r in csv.reader(open(a.g173))]
    data = np.array([[float(v) for v in r[:4]] for r in rows if r and re.match(r'^\d', r[0])])
    lam = data[:, 0]
    out = {}
    for name, col in (('extraterrestrial', 1), ('direct normal, AM1.5 (sun elevation 41.81 deg)', 3)):
        spd = np.interp(p.lam, lam, data[:, col])
        out[name] = p.cct_duv(spd @ p.cmf)
        if col == 3:
            out['xyz'] = spd @ p.cmf
    print('\n## ASTM G173-03 reference spectra (SMARTS 2.9.2 model): CCT and Duv\n')
    for name, td in out.items():
        if name != 'xyz':
            print(f'- {name}: {td[0]:.0f} K (Duv {td[1]:+.4f})')
    return out


def atmosphere_table():
    """The 48 bins of bake/model/spectral_tables.cc: nm, solar, Rayleigh, Mie scattering and extinction, ozone."""
    src = open(os.path.join(ROOT, 'bake/model/spectral_tables.cc')).read()
    return np.array([[float(v) for v in m.groups()] for m in re.finditer(
        r'\{(\d+\.0), ([\d.e+-]+), ([\d.e+-]+), ([\d.e+-]+), ([\d.e+-]+), ([\d.e+-]+)\}', src)])


def binned_xyz(p, lam_centres, values):
    """XYZ of a spectrum constant over 10 nm bins centred on lam_centres (as the spectral mode's bins)."""
    spd = np.zeros_like(p.lam)
    for lam, e in zip(lam_centres, values):
        spd[(p.lam >= lam - 5) & (p.lam < lam + 5)] = e
    return spd @ p.cmf


def beer_lambert_sun(p, atm, elevation_deg, bottom=6360.0, top=6460.0, steps=4000):
    """The default style's direct beam by Beer-Lambert through its own 48-bin atmosphere (an independent check
    of what the spectral mode's manifest reports): Rayleigh (H 8 km) + Mie extinction (H 1.2 km) + ozone
    (tent 10-40 km, peak 25 km), optical depth integrated along the slant path from the ground."""
    mu = math.sin(math.radians(elevation_deg))
    length = -bottom * mu + math.sqrt((bottom * mu) ** 2 + top ** 2 - bottom ** 2)
    s = (np.arange(steps) + 0.5) * length / steps
    h = np.sqrt(bottom ** 2 + s ** 2 + 2 * bottom * s * mu) - bottom
    ds = length / steps
    depth_r = np.exp(-h / 8.0).sum() * ds
    depth_m = np.exp(-h / 1.2).sum() * ds
    depth_o = np.clip(1 - np.abs(h - 25.0) / 15.0, 0, None).sum() * ds
    tau = atm[:, 2] * depth_r + atm[:, 4] * depth_m + atm[:, 5] * depth_o
    return binned_xyz(p, atm[:, 0], atm[:, 1] * np.exp(-tau))


def toa_sun(p, quiet=False):
    """The style's extraterrestrial Sun, the 48-bin table of bake/model/spectral_tables.cc."""
    atm = atmosphere_table()
    td = p.cct_duv(binned_xyz(p, atm[:, 0], atm[:, 1]))
    if not quiet:
        print(f'\n# skybake\'s extraterrestrial Sun (48 x 10 nm bins, ASTM G-173 ETR bin means): {td[0]:.0f} K '
              f'(Duv {td[1]:+.4f})')
    return td


def reference_table(a, p, g173):
    """skybake at the published sources' own conditions: ASTM G173's elevation, aerosol and ozone; Abbot's two
    noon elevations (their mean spectrum: the sum of the two beams)."""
    sched = write_schedule(os.path.join(a.out, 'references.toml'),
                           [(G173_ELEVATION, 135.0)] + [(e, 180.0) for e in ABBOT_ELEVATIONS])
    xyz = {}
    for name, extra in (('default', []), ('g173', G173_ATM), ('day', DAY_MIE)):
        if name == 'g173' and not g173:
            continue
        m = bake(a, os.path.join(a.out, f'references_{name}'), sched, 16, MODES['spectral48'] + extra)
        xyz[name] = [sun_xyz(m, f, 'spectral48') for f in range(3)]
    cells = lambda name, frames: '{:.0f} K ({:+.4f})'.format(*p.cct_duv(sum(xyz[name][f] for f in frames)))
    print('\n## The Sun against published figures: CCT and Duv (ours: the 48-bin spectral mode)\n')
    print('| source | kind | sun elevation | published | ours, default style | ours, source\'s aerosol and ozone '
          '| ours, Kider-day aerosol |')
    print('| --- | --- | ---: | ---: | ---: | ---: | ---: |')
    if g173:
        t, d = g173['direct normal, AM1.5 (sun elevation 41.81 deg)']
        print(f'| ASTM G173-03 direct normal | model (SMARTS 2.9.2) | 41.81 deg | {t:.0f} K ({d:+.4f}) | '
              f'{cells("default", [0])} | {cells("g173", [0])} | {cells("day", [0])} |')
        t, d = g173['extraterrestrial']
        toa = toa_sun(p, quiet=True)
        print(f'| ASTM G173-03 extraterrestrial | tabulated ETR | (top of the atmosphere) | {t:.0f} K ({d:+.4f}) | '
              f'{toa[0]:.0f} K ({toa[1]:+.4f}) | | |')
    print(f'| Abbot (Troland 1922), mean noon sunlight, Washington | measured | 27.66 and 74.54 deg, mean spectrum '
          f'| about 5000 K | {cells("default", [1, 2])} | (not known) | {cells("day", [1, 2])} |')
    if g173:
        print('\nu\'v\' distance to ASTM G173-03 direct normal at 41.81 deg: ' + ', '.join(
            f'{label} {np.linalg.norm(uv76(xyz[name][0]) - uv76(g173["xyz"])):.4f}'
            for name, label in (('default', 'default style'), ('g173', 'G173 aerosol and ozone'),
                                ('day', 'Kider-day aerosol'))))
    return xyz


def kider_table(a, p):
    gt = os.path.join(a.groundtruth, 'kider2014')
    caps = list(csv.DictReader(open(os.path.join(gt, 'captures.csv'))))
    dirs = {int(r['index']): (90.0 - float(r['view_zenith_deg']), float(r['view_azimuth_deg']))
            for r in csv.DictReader(open(os.path.join(gt, 'directions.csv')))}
    meas = {}
    for r in csv.DictReader(open(os.path.join(gt, 'photometric.csv'))):
        meas.setdefault(r['capture_id'], {})[int(r['index'])] = np.array(
            [float(r['X_cd_m2']), float(r['Y_cd_m2']), float(r['Z_cd_m2'])])
    frames = [(90.0 - float(c['sun_zenith_deg']), float(c['sun_azimuth_symmetry_deg'])) for c in caps]
    sched = write_schedule(os.path.join(a.out, 'kider.toml'), frames)
    imgs = {}
    for aerosol, mie in (('default', []), ('day', DAY_MIE)):
        for mode in ('spectral48', 'rgb'):
            out = os.path.join(a.out, f'kider_{aerosol}_{mode}')
            bake(a, out, sched, a.kider_size, MODES[mode] + mie)
            imgs[(aerosol, mode)] = [read_exr(os.path.join(out, f'sky_latlong.{i + 1:04d}.exr'))
                                     for i in range(len(caps))]
    keys = [('default', 'spectral48'), ('default', 'rgb'), ('day', 'spectral48'), ('day', 'rgb')]
    rows = []
    for i, c in enumerate(caps):
        sun = direction(*frames[i])
        idx = list(range(81))
        near = [k for k in idx if math.degrees(math.acos(min(1.0, float(direction(*dirs[k]) @ sun)))) <= NEAR_SUN_DEG]
        nearest = min(idx, key=lambda k: -float(direction(*dirs[k]) @ sun))
        sep = math.degrees(math.acos(min(1.0, float(direction(*dirs[nearest]) @ sun))))
        row = {'capture': c['capture_id'], 'elevation': frames[i][0], 'azimuth': frames[i][1], 'n_near': len(near),
               'nearest_sep': sep}
        for region, ks in (('nearest', [nearest]), ('near', near), ('sky', idx)):
            row[('xyz', 'meas', region)] = sum(meas[c['capture_id']][k] for k in ks)
            row[('meas', region)] = p.cct_duv(row[('xyz', 'meas', region)])
            for key in keys:
                row[('xyz', key, region)] = sum(REC709_TO_XYZ @ sample_latlong(imgs[key][i], direction(*dirs[k]))
                                                for k in ks)
                row[(key, region)] = p.cct_duv(row[('xyz', key, region)])
        rows.append(row)
    for aerosol in ('default', 'day'):
        read = lambda mode, i, k: uv76(REC709_TO_XYZ @ sample_latlong(imgs[(aerosol, mode)][i], direction(*dirs[k])))
        worst = max(np.linalg.norm(read('rgb', i, k) - read('spectral48', i, k))
                    for i in range(len(caps)) for k in range(81))
        print(f'\n# Kider directions, three wavelengths against 48 bins ({aerosol} aerosol): worst u\'v\' {worst:.4f} '
              f'over {len(caps)} x 81 directions')
    labels = ['measured', 'ours 48-bin', 'ours 3 wl', 'ours 48-bin, day aerosol', 'ours 3 wl, day aerosol']
    for region, title in (('nearest', 'the sky sample nearest the Sun (the disc itself is in none)'),
                          ('near', f'the sky samples within {NEAR_SUN_DEG:.0f} deg of the Sun, summed'),
                          ('sky', 'the whole sky (all 81 equal-area samples summed)')):
        print(f'\n## Kider 2014, {title}: CCT and Duv\n')
        print('| capture (EDT) | sun elevation | samples | ' + ' | '.join(labels) + ' |')
        print('| --- | ---: | ---: |' + ' ---: |' * len(labels))
        for r in rows:
            cells = [r[('meas', region)]] + [r[(k, region)] for k in keys]
            n = {'nearest': f"1, {r['nearest_sep']:.1f} deg away", 'near': str(r['n_near']), 'sky': '81'}[region]
            print(f"| {r['capture'][13:18].replace('.', ':')} | {r['elevation']:.1f} deg | {n} | " +
                  ' | '.join(f'{t:.0f} K ({d:+.4f})' for t, d in cells) + ' |')
        print()
        for j, lab in enumerate(labels[1:]):
            diff = [r[(keys[j], region)][0] - r[('meas', region)][0] for r in rows]
            dduv = [r[(keys[j], region)][1] - r[('meas', region)][1] for r in rows]
            duv = [np.linalg.norm(uv76(r[('xyz', keys[j], region)]) - uv76(r[('xyz', 'meas', region)])) for r in rows]
            print(f'- {lab} minus measured: CCT {np.mean(diff):+.0f} K on average '
                  f'({min(diff):+.0f} .. {max(diff):+.0f}), '
                  f'Duv {np.mean(dduv):+.4f}; u\'v\' distance mean {np.mean(duv):.4f}, worst {max(duv):.4f}')
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--skybake', default=os.path.join(ROOT, 'build/skybake'))
    ap.add_argument('--out', default='/tmp/skybake_sun_temperature')
    ap.add_argument('--groundtruth', default=os.path.join(os.path.dirname(ROOT), 'shared/groundtruth'))
    ap.add_argument('--g173', help='ASTM G173-03 CSV (wavelength, extraterrestrial, global, direct)')
    ap.add_argument('--kider-size', type=int, default=64, help='cube size of the Kider bakes (latlong 2N x N)')
    ap.add_argument('--reuse', action='store_true', help='read bakes already in --out instead of baking again')
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    p = Planck(os.path.join(a.groundtruth, 'constants/cie1931_2deg_5nm.csv'))
    self_check(p)
    print(f'# Kider-day aerosol: AOD {DAY_AOD[2]:.3f} / {DAY_AOD[1]:.3f} / {DAY_AOD[0]:.3f} at 440/550/680 nm '
          f'(the default style: 0.0053 at every wavelength): ' + ' '.join(DAY_MIE[1::2]))
    toa_sun(p)
    g173 = g173_table(a, p) if a.g173 else None
    sun_table(a, p)
    reference_table(a, p, g173)
    kider_table(a, p)
    return 0


if __name__ == '__main__':
    sys.exit(main())
