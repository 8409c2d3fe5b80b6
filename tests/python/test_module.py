"""The Python module against the CLI: the same bytes, arrays that are the files' texels,
errors with the CLI's exit codes and locations, progress events, cancellation."""
import hashlib
import json
import os
import pathlib
import subprocess
import sys
import threading

import numpy as np
import pytest

import skybake

STYLE = "configs/default.toml"
SIZE = 16

# A short time-lapse: three clock times at Rhodes Hall (configs/schedules/day.toml's place).
SCHEDULE = """\
[schedule]
first_frame = 1
date = 2013-05-27
latitude_deg = 42.44337
longitude_deg = -76.48163
utc_offset_hours = -4.0
times = [07:00:00, 12:00:00, 19:30:00]
"""


@pytest.fixture(scope="module")
def schedule_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("schedule") / "three.toml"
    path.write_text(SCHEDULE)
    return path


def folder_bytes(folder):
    """Every file of a bake's folder by name (timings.json apart: it holds times)."""
    return {p.name: p.read_bytes() for p in pathlib.Path(folder).iterdir() if p.name != "timings.json"}


def hidden(folder):
    return sorted(p.name for p in pathlib.Path(folder).iterdir() if p.name.startswith("."))


def assert_same_folders(cli_dir, python_dir):
    cli_files, python_files = folder_bytes(cli_dir), folder_bytes(python_dir)
    assert sorted(cli_files) == sorted(python_files)
    different = [name for name in cli_files if cli_files[name] != python_files[name]]
    assert different == []


# === Bytes: the module bakes what the CLI bakes.

def test_the_cli_and_the_module_are_one_build(cli):
    """The manifest records the build's commit: the byte comparisons need both built from one checkout."""
    assert cli("--version").stdout.strip() == f"skybake {skybake.__version__} (commit {skybake.commit})", \
        "rebuild skybake and skybake_python together"


def test_single_bake_gives_the_cli_bytes(cli, in_source, tmp_path):
    run = cli("bake", STYLE, "--size", SIZE, "--out", tmp_path / "cli", "--vulkan-validation", "-q")
    assert run.returncode == 0, run.stderr
    result = skybake.bake(skybake.load_style(STYLE), out=str(tmp_path / "py"), size=SIZE, vulkan_validation=True)
    assert_same_folders(tmp_path / "cli", tmp_path / "py")
    # The result names the manifest's files with their checksums.
    listed = {f["file"]: f["sha256"] for frame in result.manifest["frames"] for f in frame["files"]}
    frame_files = {pathlib.Path(f.path).name: f.sha256 for f in result.frames[0].files}
    assert listed == frame_files
    assert result.manifest["commit"] == skybake.commit
    assert result.manifest["complete"] is True


def test_sequence_gives_the_cli_bytes(cli, in_source, tmp_path, schedule_path):
    """A time-lapse of clock times, baked from a fresh Python process as the CLI bakes it from its
    own (the sun positions of clock times depend on what the process computed before them:
    test_sun_positions_do_not_depend_on_earlier_ones)."""
    run = cli("bake", STYLE, "--schedule", schedule_path, "--size", SIZE, "--out", tmp_path / "cli",
              "--vulkan-validation", "-q")
    assert run.returncode == 0, run.stderr
    script = f"""
import json, skybake
result = skybake.bake(skybake.load_style({STYLE!r}), out={str(tmp_path / "py")!r}, size={SIZE},
                      schedule=skybake.load_schedule({str(schedule_path)!r}), vulkan_validation=True)
print(json.dumps([[f.number, f.time, f.sun_elevation_deg] for f in result.frames]))
"""
    env = dict(os.environ, PYTHONPATH=os.path.dirname(skybake.__file__))
    baked = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True)
    assert baked.returncode == 0, baked.stderr
    assert_same_folders(tmp_path / "cli", tmp_path / "py")
    frames = json.loads(baked.stdout)
    manifest = json.loads((tmp_path / "py" / "manifest.json").read_text())
    assert [f[0] for f in frames] == [1, 2, 3]
    for (number, time, elevation), record in zip(frames, manifest["frames"]):
        assert time == record["time"] and elevation == record["sun"]["elevation_deg"]


def test_dict_style_bakes_as_its_toml(in_source, tmp_path):
    """A dict is the same style as the file with those keys: the same resolved TOML and bytes."""
    (tmp_path / "noon.toml").write_text('[sun]\nelevation_deg = 35.5\nazimuth_deg = 120\n')
    from_file = skybake.load_style(str(tmp_path / "noon.toml"))
    from_dict = skybake.load_style({"sun": {"elevation_deg": 35.5, "azimuth_deg": 120}}, name=str(tmp_path / "noon.toml"))
    assert from_dict.toml == from_file.toml
    a = skybake.bake(from_file, out=str(tmp_path / "file"), size=SIZE, vulkan_validation=True)
    b = skybake.bake(from_dict, out=str(tmp_path / "dict"), size=SIZE, vulkan_validation=True)
    assert_same_folders(tmp_path / "file", tmp_path / "dict")
    assert a.frames[0].sun_elevation_deg == pytest.approx(35.5, abs=1e-6)
    assert a.frames[0].sun_azimuth_deg == pytest.approx(120.0, abs=1e-6)
    assert b.frames[0].illuminance_lux > 0


def test_sun_positions_do_not_depend_on_earlier_ones(schedule_path, tmp_path):
    """The same schedule gives the same sun positions whatever was computed before it in the process."""
    first = skybake.load_schedule(str(schedule_path)).frames
    other = tmp_path / "other.toml"
    other.write_text(SCHEDULE.replace("times = [07:00:00, 12:00:00, 19:30:00]", "times = [19:45:00]"))
    skybake.load_schedule(str(other))
    assert skybake.load_schedule(str(schedule_path)).frames == first


def test_dict_style_sequence_bakes_as_its_file(in_source, tmp_path):
    """Each frame's style of a dict style is resolved from its TOML text as a file's from the file:
    the same bytes, with a ramp changing a key per frame."""
    (tmp_path / "hazy.toml").write_text('[atmosphere.mie]\ng = 0.7\n')
    schedule = tmp_path / "ramp.toml"
    schedule.write_text('[schedule]\nfirst_frame = 1\n'
                        + "".join(f'[[schedule.frames]]\nelevation_deg = {e}\nazimuth_deg = 135.0\n' for e in (5, 25, 45))
                        + '[schedule.ramp]\n"atmosphere.mie.g" = [0.7, 0.85]\n')
    from_dict = skybake.load_style({"atmosphere": {"mie": {"g": 0.7}}}, name=str(tmp_path / "hazy.toml"))
    for style, out in [(skybake.load_style(str(tmp_path / "hazy.toml")), "file"), (from_dict, "dict")]:
        result = skybake.bake(style, out=str(tmp_path / out), size=SIZE, schedule=skybake.load_schedule(str(schedule)))
    assert len({frame["style_sha256"] for frame in result.manifest["frames"]}) == 3
    assert_same_folders(tmp_path / "file", tmp_path / "dict")


def test_dict_style_inline_schedule_bakes_as_the_cli(cli, tmp_path):
    """A dict with a [schedule] table is a sequence, as a style file with one is to the CLI: the
    schedule's date and times as datetime objects (TOML dates and times), a ramp; the same bytes."""
    import datetime
    path = tmp_path / "inline.toml"
    path.write_text('[atmosphere.mie]\ng = 0.7\n'
                    '[schedule]\nfirst_frame = 1\ndate = 2013-05-27\nlatitude_deg = 42.44337\n'
                    'longitude_deg = -76.48163\nutc_offset_hours = -4.0\ntimes = [07:00:00, 12:30:00]\n'
                    '[schedule.ramp]\n"atmosphere.mie.g" = [0.7, 0.85]\n')
    from_dict = skybake.load_style(
        {"atmosphere": {"mie": {"g": 0.7}},
         "schedule": {"first_frame": 1, "date": datetime.date(2013, 5, 27), "latitude_deg": 42.44337,
                      "longitude_deg": -76.48163, "utc_offset_hours": -4.0,
                      "times": [datetime.time(7, 0), datetime.time(12, 30)],
                      "ramp": {"atmosphere.mie.g": [0.7, 0.85]}}}, name=str(path))
    assert from_dict.has_schedule and skybake.load_style(str(path)).has_schedule
    assert skybake.parse_style(path.read_text()).has_schedule
    assert not skybake.load_style({"atmosphere": {"mie": {"g": 0.7}}}).has_schedule
    run = cli("bake", path, "--size", SIZE, "--out", tmp_path / "cli", "--vulkan-validation", "-q")
    assert run.returncode == 0, run.stderr
    result = skybake.bake(from_dict, out=str(tmp_path / "py"), size=SIZE, vulkan_validation=True)
    assert [f.number for f in result.frames] == [1, 2]
    assert [f.time for f in result.frames] == ["2013-05-27T07:00:00-04:00", "2013-05-27T12:30:00-04:00"]
    assert len({frame["style_sha256"] for frame in result.manifest["frames"]}) == 2
    assert_same_folders(tmp_path / "cli", tmp_path / "py")
    # plan and check read it as the CLI does.
    assert skybake.plan(from_dict) == cli("plan", path).stdout
    # An inline schedule's mistakes are StyleErrors at their key, nothing baked.
    bad = {"schedule": {"date": "2013-05-27", "times": [datetime.time(7, 0)]}}
    with pytest.raises(skybake.StyleError) as raised:
        skybake.bake(skybake.load_style(bad, name="bad"), out=str(tmp_path / "bad"), size=SIZE)
    assert ("bad", "schedule.date") in [(x.file, x.key) for x in raised.value.errors]
    assert not (tmp_path / "bad").exists()
    with pytest.raises(skybake.StyleError) as raised:
        skybake.load_style({"schedule": {"times": [datetime.time(7, tzinfo=datetime.timezone.utc)]}})
    assert [x.key for x in raised.value.errors] == ["schedule.times[0]"]


# === Arrays: the files' texels.

def read_with_oiiotool(exr):
    """OpenImageIO's reading of an EXR: every texel's RGB as oiiotool --dumpdata prints it
    (exact for half floats)."""
    run = subprocess.run(["oiiotool", "--dumpdata", str(exr)], check=True, capture_output=True, text=True)
    header, *lines = run.stdout.splitlines()
    width, height = (int(v) for v in header.split(":")[1].split(",")[0].split("x"))
    texels = np.full((height, width, 3), np.nan, dtype=np.float32)
    for line in lines:
        where, values = line.split(":")
        x, y = (int(v) for v in where.strip()[len("Pixel ("):-1].split(","))
        texels[y, x] = [float(v) for v in values.split()[:3]]
    return texels


def test_arrays_are_the_files_texels(in_source, tmp_path):
    result = skybake.bake(skybake.load_style(STYLE), out=str(tmp_path / "out"), size=SIZE, arrays=True,
                          vulkan_validation=True)
    frame = result.frames[0]
    assert frame.latlong.dtype == np.float32 and frame.latlong.shape == (SIZE, 2 * SIZE, 3)
    latlong_file = next(f.path for f in frame.files if f.kind == "latlong" and f.path.endswith(".exr"))
    np.testing.assert_array_equal(frame.latlong, read_with_oiiotool(latlong_file))
    face_files = [f.path for f in frame.files if f.kind == "face"]
    assert len(face_files) == 6 and sorted(frame.faces) == sorted(pathlib.Path(p).name for p in face_files)
    for path in face_files:
        face = frame.faces[pathlib.Path(path).name]
        assert face.shape == (SIZE, SIZE, 3)
        np.testing.assert_array_equal(face, read_with_oiiotool(path))
    # Lighting as numbers: SH of the sky, the Sun above the horizon.
    assert frame.sh_with_sun.shape == (9, 3) and frame.sh_with_sun[0].min() > frame.sh_without_sun[0].min() > 0
    assert frame.moon is None


def test_engine_arrays_are_the_files_texels(in_source, tmp_path):
    result = skybake.bake(skybake.load_style(STYLE), out=str(tmp_path / "out"), size=SIZE, arrays=True,
                          engine="blender")
    frame = result.frames[0]
    assert sorted(frame.engine) == ["sky_blender_latlong.exr"]
    np.testing.assert_array_equal(frame.engine["sky_blender_latlong.exr"],
                                  read_with_oiiotool(tmp_path / "out" / "sky_blender_latlong.exr"))


# A small IBL bake: two specular levels, the irradiance and the DFG table, as EXRs and KTX2s.
IBL = ["ibl.specular=true", "ibl.irradiance=true", "ibl.dfg_lut=true", "ibl.size=16", "ibl.samples=16",
       "ibl.irradiance_size=8", "ibl.irradiance_samples=16", "ibl.dfg_size=8", "ibl.dfg_samples=16", "ibl.ktx2=true"]


def read_small_values_with_oiiotool(exr, tmp_path):
    """read_with_oiiotool exact for every half float, subnormals too (--dumpdata prints 9 decimals):
    OpenImageIO scales the texels by 2^24 into a float EXR first (every half is then a whole number)."""
    scaled = tmp_path / f"scaled_{exr.name}"
    subprocess.run(["oiiotool", str(exr), "--mulc", str(2 ** 24), "-d", "float", "-o", str(scaled)], check=True)
    return read_with_oiiotool(scaled) / np.float32(2 ** 24)


def read_ktx2_with_ktx_parse(source_dir, ktx2, tmp_path):
    """npm ktx-parse's reading of a KTX2 (tests/viewer/ktx2_dump.mjs, zstd undone by the zstd
    command): each mip level's texels as RGB float32, (faces, N, N, 3), decoded here with numpy."""
    prefix = tmp_path / ktx2.name
    run = subprocess.run(["node", "ktx2_dump.mjs", str(ktx2), str(prefix)], cwd=source_dir / "tests" / "viewer",
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    info = json.loads(run.stdout)
    faces = info["faceCount"]
    levels = []
    for i in range(info["levelCount"]):
        n = max(1, info["pixelWidth"] >> i)
        raw = (tmp_path / f"{ktx2.name}.level{i}").read_bytes()
        if info["vkFormat"] == 97:  # R16G16B16A16_SFLOAT
            rgb = np.frombuffer(raw, dtype="<f2").reshape(faces, n, n, 4)[..., :3].astype(np.float32)
        elif info["vkFormat"] == 122:  # B10G11R11_UFLOAT_PACK32: R 6+5 bits, G 6+5, B 5+5 (exponent bias 15)
            v = np.frombuffer(raw, dtype="<u4").reshape(faces, n, n)

            def unsigned_float(bits, mantissa_bits):
                e = (bits >> mantissa_bits).astype(np.int32)
                m = (bits & ((1 << mantissa_bits) - 1)).astype(np.float64) / (1 << mantissa_bits)
                assert (e < 31).all()  # no infinity or NaN in a bake's maps
                return np.where(e == 0, np.ldexp(m, -14), np.ldexp(1.0 + m, e - 15))

            rgb = np.stack([unsigned_float(v & 0x7FF, 6), unsigned_float((v >> 11) & 0x7FF, 6),
                            unsigned_float(v >> 22, 5)], axis=-1).astype(np.float32)
        else:
            assert info["vkFormat"] == 123  # E5B9G9R9_UFLOAT_PACK32: mantissa 2^(exponent - 15 - 9)
            v = np.frombuffer(raw, dtype="<u4").reshape(faces, n, n)
            scale = np.ldexp(1.0, (v >> 27).astype(np.int32) - 24)
            rgb = np.stack([((v >> (9 * c)) & 0x1FF) * scale for c in range(3)], axis=-1).astype(np.float32)
        levels.append(rgb if faces == 6 else rgb[0])
    return levels


@pytest.mark.parametrize("ktx2", [["ibl.ktx2_zstd_level=3"], ["ibl.ktx2_format=\"e5b9g9r9\"", "ibl.exr=false"],
                                  ["ibl.ktx2_format=\"b10g11r11\"", "ibl.exr=false", "ibl.ktx2_zstd_level=1"]],
                         ids=["rgba16f_zstd", "e5b9g9r9_without_exr", "b10g11r11_zstd_without_exr"])
def test_ibl_arrays_are_the_files_texels(in_source, source_dir, tmp_path, ktx2):
    """Every IBL file's texels (EXRs read back by OpenImageIO, KTX2 mip levels by npm ktx-parse);
    .ibl_specular and .ibl_irradiance from the EXRs when written, else from the KTX2s."""
    result = skybake.bake(skybake.load_style(STYLE, IBL + ktx2), out=str(tmp_path / "out"), size=SIZE, arrays=True,
                          vulkan_validation=True)
    frame = result.frames[0]
    ibl_files = [pathlib.Path(f.path) for f in frame.files if f.kind.startswith("ibl_")]
    with_exr = "ibl.exr=false" not in ktx2
    assert sorted(frame.ibl) == sorted(p.name for p in ibl_files) and len(ibl_files) == (7 if with_exr else 3)
    for path in ibl_files:
        array = frame.ibl[path.name]
        if path.suffix == ".exr":
            texels = read_small_values_with_oiiotool(path, tmp_path)
            if path.name != "sky_dfg.exr":
                n = texels.shape[1]
                texels = texels.reshape(6, n, n, 3)  # six faces stacked from the top
            assert array.dtype == np.float32
            np.testing.assert_array_equal(array, texels)
        else:
            levels = read_ktx2_with_ktx_parse(source_dir, path, tmp_path)
            assert len(array) == len(levels)
            for got, read in zip(array, levels):
                assert got.dtype == np.float32
                np.testing.assert_array_equal(got, read)
    assert [level.shape for level in frame.ibl_specular] == [(6, 16, 16, 3), (6, 8, 8, 3)]
    assert frame.ibl_irradiance.shape == (6, 8, 8, 3)
    if with_exr:
        assert frame.ibl_specular[1] is frame.ibl["sky_specular_m1.exr"]
        assert frame.ibl_irradiance is frame.ibl["sky_irradiance.exr"]
    else:
        assert frame.ibl_specular[1] is frame.ibl["sky_specular.ktx2"][1]
        assert frame.ibl_irradiance is frame.ibl["sky_irradiance.ktx2"][0]
    # The maps are of a daylit sky: positive; the irradiance is smoother than level 0.
    assert frame.ibl_irradiance.min() > 0 and frame.ibl_specular[0].min() > 0
    assert frame.ibl_irradiance.std() < frame.ibl_specular[0].std()


def test_without_arrays_no_images_are_read(in_source, tmp_path):
    result = skybake.bake(skybake.load_style(STYLE, IBL), out=str(tmp_path / "out"), size=SIZE)
    frame = result.frames[0]
    assert frame.latlong is None and frame.faces == {} and frame.ibl == {}
    assert frame.ibl_specular == [] and frame.ibl_irradiance is None


def test_moon_and_lights_are_the_manifests(in_source, tmp_path):
    """A moonlit frame (Cerro Paranal, the full moon of 2024-04-23): the Moon and the Sun as the
    manifest records them."""
    schedule = tmp_path / "moon.toml"
    schedule.write_text("[schedule]\nfirst_frame = 1\ndate = 2024-04-23\nlatitude_deg = -24.6272\n"
                        "longitude_deg = -70.4042\nutc_offset_hours = -4.0\ntimes = [23:30:00]\n")
    result = skybake.bake(skybake.load_style(STYLE, ["night.moon=true", "night.moonlight=true"]),
                          out=str(tmp_path / "out"), size=SIZE, schedule=skybake.load_schedule(str(schedule)),
                          vulkan_validation=True)
    frame, record = result.frames[0], result.manifest["frames"][0]
    assert frame.sun_elevation_deg < 0 < frame.moon["elevation_deg"]
    assert {k: list(v) if isinstance(v, tuple) else v for k, v in frame.moon.items()} == record["moon"]
    assert frame.illuminance_lux == record["sun"]["illuminance_lux"]
    assert list(frame.sun_direction) == record["sun"]["direction"]
    assert frame.sh_with_sun.tolist() == record["sh_irradiance_with_sun"]


# === Inputs read again by each bake.

def test_a_bake_after_an_edit_reads_the_edited_inputs(in_source, source_dir, tmp_path):
    """Each call reads its input files as they are then (one bake still reads each once): an
    OpenColorIO config edited between two bakes in one process changes the second bake's maps.
    The edit halves the matrix of "Linear P3-D65" (XYZ to P3): the maps halve."""
    config = tmp_path / "config.ocio"
    original = (source_dir / "tests" / "colour" / "ocio" / "test_config.ocio").read_text()
    config.write_text(original)
    overrides = ['output.color_space="Linear P3-D65"', f'output.ocio_config="{config}"']
    first = skybake.bake(skybake.load_style(STYLE, overrides), out=str(tmp_path / "first"), size=SIZE, arrays=True)
    matrix = "matrix: [2.493496911941425, -0.9313836179191239, -0.40271078445071684, 0, -0.8294889695615747, " \
             "1.7626640603183463, 0.023624685841943577, 0, 0.03584583024378447, -0.07617238926804182, " \
             "0.9568845240076872, 0, 0, 0, 0, 1]"
    assert matrix in original
    halved = "matrix: [" + ", ".join(repr(float(v) * 0.5) if i not in (3, 7, 11, 15) else v
                                     for i, v in enumerate(matrix[len("matrix: ["):-1].split(", "))) + "]"
    config.write_text(original.replace(matrix, halved))
    style = skybake.load_style(STYLE, overrides)
    second = skybake.bake(style, out=str(tmp_path / "second"), size=SIZE, arrays=True)
    a, b = first.frames[0].latlong, second.frames[0].latlong
    assert a.min() > 0 and not np.array_equal(a, b)
    np.testing.assert_allclose(b, 0.5 * a, rtol=2 ** -10)  # half floats: 11 significant bits
    # The style loaded after the edit holds the edited matrix too; bake() re-reads.
    config.write_text(original)
    third = skybake.bake(style, out=str(tmp_path / "third"), size=SIZE, arrays=True)
    np.testing.assert_array_equal(third.frames[0].latlong, a)


# === Errors: the CLI's exit codes and located messages.

def test_style_file_errors_are_located_as_the_cli_gives_them(cli, tmp_path):
    style = tmp_path / "typo.toml"
    style.write_text('[sun]\nelevation_deg = 30\nturbidty = 3\n[atmosphere.mie]\ng = "forward"\n')
    with pytest.raises(skybake.StyleError) as raised:
        skybake.load_style(str(style))
    e = raised.value
    assert e.exit_code == 3 and isinstance(e, skybake.Error)
    assert sorted((x.file, x.line, x.key) for x in e.errors) == [(str(style), 3, "sun.turbidty"),
                                                                 (str(style), 5, "atmosphere.mie.g")]
    run = cli("check", style)
    assert run.returncode == e.exit_code
    for x in e.errors:
        assert f"skybake: error: {x.file}:{x.line}:{x.column}: {x.key}: {x.message}" in run.stderr


def test_dict_with_wrong_types(tmp_path):
    with pytest.raises(skybake.StyleError) as raised:
        skybake.load_style({"sun": {"elevation_deg": "high"}})
    assert raised.value.exit_code == 3
    assert [(x.file, x.key) for x in raised.value.errors] == [("<dict>", "sun.elevation_deg")]
    with pytest.raises(skybake.StyleError) as raised:
        skybake.load_style({"sun": {"elevation_deg": None}, "render": {"cube_size": [1, object()]}})
    assert sorted(x.key for x in raised.value.errors) == ["render.cube_size[1]", "sun.elevation_deg"]


def test_bad_input_raises_the_clis_errors_and_writes_nothing(cli, in_source, tmp_path):
    """The issue's bad input, from Python as from the command: a dict of wrong types, an unknown
    colour space (dict, override and file), a USD layer that cannot be written; each the CLI's
    exit code and located message, and nothing written."""
    # A dict of wrong types: the messages of the same keys in a file, at their keys.
    style_file = tmp_path / "wrong.toml"
    style_file.write_text('[sun]\nelevation_deg = "high"\n[render]\ncube_size = 12.5\n')
    with pytest.raises(skybake.StyleError) as from_dict:
        skybake.load_style({"sun": {"elevation_deg": "high"}, "render": {"cube_size": 12.5}}, name=str(style_file))
    run = cli("check", style_file)
    assert run.returncode == from_dict.value.exit_code == 3
    assert sorted(x.key for x in from_dict.value.errors) == ["render.cube_size", "sun.elevation_deg"]
    for x in from_dict.value.errors:
        assert f": {x.key}: {x.message}" in run.stderr

    # An unknown colour space: the names there are, at output.color_space; nothing baked.
    run = cli("bake", STYLE, "--size", SIZE, "--set", 'output.color_space="P4"', "--out", tmp_path / "cli")
    assert run.returncode == 3 and not (tmp_path / "cli").exists()
    for style in [lambda: skybake.load_style({"output": {"color_space": "P4"}}),
                  lambda: skybake.load_style(STYLE, ['output.color_space="P4"'])]:
        with pytest.raises(skybake.StyleError) as raised:
            skybake.bake(style(), out=str(tmp_path / "py"), size=SIZE)
        assert raised.value.exit_code == 3
        [error] = raised.value.errors
        assert error.key == "output.color_space"
        assert "'P4' is not one of 'rec709', 'acescg', 'aces2065-1', 'rec2020', 'xyz'" in error.message
        assert f"output.color_space: {error.message}" in run.stderr
    assert not (tmp_path / "py").exists()

    # A USD layer that cannot be written (a folder at its name): exit code 5 before any file.
    for name in ["cli", "py"]:
        (tmp_path / "usd" / name / "sky.usda").mkdir(parents=True)
    run = cli("bake", STYLE, "--size", SIZE, "--usd", "--out", tmp_path / "usd" / "cli")
    with pytest.raises(skybake.OutputError) as raised:
        skybake.bake(skybake.load_style(STYLE), out=str(tmp_path / "usd" / "py"), size=SIZE, usd=True)
    assert run.returncode == raised.value.exit_code == 5
    message = str(raised.value)
    assert message == f"{tmp_path / 'usd' / 'py'}/sky.usda is a directory: an output file cannot replace it; " \
                      "move it away, or choose another --out"
    assert run.stderr == "skybake: error: " + message.replace("/py/", "/cli/") + "\n"
    for name in ["cli", "py"]:
        assert [p.name for p in (tmp_path / "usd" / name).iterdir()] == ["sky.usda"]
        assert list((tmp_path / "usd" / name / "sky.usda").iterdir()) == []


def test_dict_values_as_toml():
    """numpy scalars are numbers; strings keep quotes, backslashes and newlines (the error quotes
    the value read back); a dict equals the TOML text of the same keys."""
    from_dict = skybake.load_style({"sun": {"elevation_deg": np.float32(10.5), "azimuth_deg": np.int64(90)}})
    from_text = skybake.parse_style("[sun]\nelevation_deg = 10.5\nazimuth_deg = 90\n", name="<dict>")
    assert from_dict.toml == from_text.toml
    with pytest.raises(skybake.StyleError) as raised:
        skybake.load_style({"output": {"basename": 'a"b\\c\nd'}})
    assert raised.value.errors[0].key == "output.basename"
    assert raised.value.errors[0].message.startswith("'a\"b\\\\c\\nd' is not a plain file name")


def test_overrides_are_checked_as_set(in_source):
    with pytest.raises(skybake.StyleError) as raised:
        skybake.load_style(STYLE, ["sun.elevation_deg=high"])
    assert raised.value.errors[0].key == "sun.elevation_deg"
    assert skybake.load_style(STYLE, ["sun.elevation_deg=12.5"]).toml != skybake.load_style(STYLE).toml


def test_schedule_errors(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[schedule]\nelevation_deg = { start = 10, end = 0, step = 5 }\nbogus = 1\n")
    with pytest.raises(skybake.StyleError) as raised:
        skybake.load_schedule(str(bad))
    assert raised.value.errors and all(x.file == str(bad) and x.line > 0 for x in raised.value.errors)


def test_folder_budget_usage_and_output_errors(in_source, tmp_path):
    style = skybake.load_style(STYLE)
    skybake.bake(style, out=str(tmp_path / "out"), size=SIZE)
    with pytest.raises(skybake.FolderError) as raised:
        skybake.bake(style, out=str(tmp_path / "out"), size=SIZE)
    assert raised.value.exit_code == 6 and "force" in str(raised.value)
    events = []
    with pytest.raises(skybake.BudgetError) as raised:
        skybake.bake(style, out=str(tmp_path / "budget"), size=SIZE, max_memory_mib=0.01, progress=events.append)
    assert raised.value.exit_code == 7 and not (tmp_path / "budget").exists()
    # The progress events end as --progress-json's: the exit code and the error.
    assert [e["event"] for e in events] == ["start", "end"]
    assert events[-1]["exit_code"] == 7 and events[-1]["error"] == str(raised.value)
    with pytest.raises(skybake.UsageError) as raised:
        skybake.bake(style, out=str(tmp_path / "usage"), size=SIZE, resume=True)
    assert raised.value.exit_code == 2
    (tmp_path / "a_file").write_text("")
    with pytest.raises(skybake.OutputError) as raised:
        skybake.bake(style, out=str(tmp_path / "a_file"), size=SIZE)
    assert raised.value.exit_code == 5


def test_vulkan_error(in_source, tmp_path, cli):
    with pytest.raises(skybake.VulkanError) as raised:
        skybake.bake(skybake.load_style(STYLE), out=str(tmp_path / "out"), size=SIZE, device=99)
    assert raised.value.exit_code == 4
    assert cli("bake", STYLE, "--size", SIZE, "--out", tmp_path / "cli", "--device", 99).returncode == 4


def test_check_and_plan(in_source, schedule_path, cli):
    style = skybake.load_style(STYLE)
    assert skybake.check(style, skybake.load_schedule(str(schedule_path))) == []
    with pytest.raises(skybake.BudgetError):
        skybake.check(style, max_memory_mib=0.01)
    run = cli("plan", STYLE)
    assert run.returncode == 0
    assert skybake.plan(style) == run.stdout


# === Progress and cancellation.

def test_progress_events(in_source, tmp_path, schedule_path):
    events = []
    skybake.bake(skybake.load_style(STYLE), out=str(tmp_path / "out"), size=SIZE,
                 schedule=skybake.load_schedule(str(schedule_path)), progress=events.append)
    kinds = [e["event"] for e in events]
    assert kinds[0] == "start" and kinds[-1] == "end" and events[-1]["exit_code"] == 0
    assert [(e["frame"], e["of"], e["number"]) for e in events if e["event"] == "frame_end"] == \
        [(1, 3, 1), (2, 3, 2), (3, 3, 3)]
    assert all({"seconds_per_frame", "eta_s"} <= set(e) for e in events if e["event"] == "frame_end")
    assert any(e["event"] == "stage" and e["stage"] == "LUTs" for e in events)


def test_cancel_leaves_a_resumable_folder(in_source, tmp_path, schedule_path):
    style, schedule = skybake.load_style(STYLE), skybake.load_schedule(str(schedule_path))
    out = tmp_path / "cancelled"
    seen = []

    def stop_after_second_frame(event):
        seen.append(event["event"])
        return not (event["event"] == "frame_end" and event["frame"] == 2)

    with pytest.raises(skybake.Cancel):
        skybake.bake(style, out=str(out), size=SIZE, schedule=schedule, progress=stop_after_second_frame)
    assert seen.count("frame_start") == 2 and "end" not in seen
    assert hidden(out) == []  # no temporaries, no lock claim
    # A valid manifest of the frames recorded, each listed file there with its checksum; frame 2,
    # in flight, was written whole but not recorded (as when a bake is killed then).
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["complete"] is False and [f["frame"] for f in manifest["frames"]] == [1]
    for f in manifest["frames"][0]["files"]:
        assert hashlib.sha256((out / f["file"]).read_bytes()).hexdigest() == f["sha256"]
    assert not any(".0003." in name for name in os.listdir(out))
    # resume finishes the bake with the bytes of an uninterrupted one, the manifest included.
    skybake.bake(style, out=str(out), size=SIZE, schedule=schedule, resume=True, vulkan_validation=True)
    skybake.bake(style, out=str(tmp_path / "whole"), size=SIZE, schedule=schedule)
    assert_same_folders(tmp_path / "whole", out)


def test_cancel_before_the_first_file_writes_nothing(in_source, tmp_path):
    out = tmp_path / "out"

    def stop(event):
        if event["event"] == "stage":
            raise skybake.Cancel("enough")

    with pytest.raises(skybake.Cancel, match="enough"):
        skybake.bake(skybake.load_style(STYLE), out=str(out), size=SIZE, progress=stop)
    assert not out.exists() or list(out.iterdir()) == []


def test_an_error_in_the_callback_cancels_and_propagates(in_source, tmp_path):
    def broken(event):
        if event["event"] == "frame_start":
            raise ZeroDivisionError("callback bug")

    with pytest.raises(ZeroDivisionError, match="callback bug"):
        skybake.bake(skybake.load_style(STYLE), out=str(tmp_path / "out"), size=SIZE, progress=broken)
    assert hidden(tmp_path / "out") == []


def test_the_gil_is_released_while_baking(in_source, tmp_path, schedule_path):
    """With no forced switching between threads, this thread runs while the bake's thread bakes
    only if the bake lets go of the GIL: it sees the bake started and not yet ended."""
    started, events, snapshot = threading.Event(), [], []

    def progress(event):
        events.append(event["event"])
        started.set()

    worker = threading.Thread(target=lambda: skybake.bake(
        skybake.load_style(STYLE), out=str(tmp_path / "out"), size=SIZE,
        schedule=skybake.load_schedule(str(schedule_path)), progress=progress))
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        worker.start()
        started.wait()
        snapshot.extend(events)
        worker.join()
    finally:
        sys.setswitchinterval(interval)
    assert snapshot[0] == "start" and "end" not in snapshot
    assert events[-1] == "end"


# === docs/python.md's Blender example, as it stands there, in Debian's Blender.

def test_blender_example_from_the_docs(source_dir, tmp_path):
    text = (source_dir / "docs" / "python.md").read_text()
    start = text.index("```python\n# blender_timelapse.py")
    script = text[start + len("```python\n"):text.index("```", start + 10)]
    (tmp_path / "blender_timelapse.py").write_text(script)
    env = dict(os.environ, PYTHONPATH=os.path.dirname(skybake.__file__))
    run = subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                          str(tmp_path / "blender_timelapse.py"), "--", str(tmp_path / "blender")],
                         cwd=source_dir, env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert "blender_timelapse: ok" in run.stdout
    assert run.stdout.count("skybake: frame ") == 4
    assert (tmp_path / "blender" / "timelapse.blend").is_file()
