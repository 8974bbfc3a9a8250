"""4096² files in the layouts of the instrument formats that neither this repository nor
SurfaceTopography writes, for bench/readers_4096_peers.py (issue 34, item 4).

Each writer starts from the real file of that format in the shared topography folders
(read at run time, never copied into the repository), keeps its header, changes the grid's
dimensions and the offsets that follow from them, and writes an n × n map of samples drawn
from `rng`. It returns the heights the file holds, in metres, as asperity's `.npy` holds
them ((y, x), row 0 as asperity orders it), computed here from the header's own scale
fields by the format's rule (the rule each reader's module documentation states), so that
both tools' readings are checked against numbers neither computed.
"""

import os
import re
import struct

import numpy as np

SHARED = os.environ.get("ASPERITY_SHARED",
                        os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                     "shared"))


def real(name):
    """The bytes of a real file of the shared folders (`topographies`, `-2`, `-3`)."""
    for folder in ("topographies", "topographies-2", "topographies-3"):
        path = os.path.join(SHARED, folder, name)
        if os.path.exists(path):
            with open(path, "rb") as f:
                return f.read()
    raise SystemExit(f"{name}: not in {SHARED}/topographies*")


def ints(rng, n, lo, hi, dtype):
    return rng.integers(lo, hi, size=(n, n)).astype(dtype)


# --- Bruker / Veeco / DI Nanoscope (di-1.di: version 7.2, 2 bytes per pixel) ------------

def write_di(path, n, rng):
    """The header's sections up to the first image section (the other three channels are
    left out, so the file is one 4096² map); its grid set to n × n (`Samps/line`, `Number
    of lines`, the scan list's `Lines`), its data at the header's fixed length (the file
    list's `Data length`, 40960). Heights: s · hard / 65536 V · Zsens nm/V, the lines
    stored from the top down (asperity's row 0 is the last line stored)."""
    b = real("di-1.di")
    text = b[:b.find(b"\\*File list end")].decode("latin1")
    sections = text.split("\\*")[1:]
    first = next(i for i, s in enumerate(sections) if s.startswith("Ciao image list"))
    head_len = int(re.search(r"\\Data length: (\d+)", sections[0]).group(1))
    kept = sections[:first + 1]
    data = ints(rng, n, -32768, 32768, "<i2")
    image = kept[-1]
    for key, value in (("Samps/line", n), ("Number of lines", n), ("Data offset", head_len),
                       ("Data length", n * n * 2)):
        image = re.sub(rf"\\{re.escape(key)}: \d+", f"\\\\{key}: {value}", image)
    kept[-1] = image
    kept = [re.sub(r"\\(Samps/line|Lines): \d+", rf"\\\1: {n}", s) if s.startswith(
        "Ciao scan list") else s for s in kept]
    header = ("\\*" + "\\*".join(kept) + "\\*File list end\r\n").encode("latin1")
    assert len(header) <= head_len
    with open(path, "wb") as f:
        f.write(header.ljust(head_len, b"\0"))
        f.write(data.tobytes())
    hard = float(re.search(r"\\@2:Z scale: V \[Sens. Zsens\] \([^)]*\) ([0-9.eE+-]+) V",
                           image).group(1))
    zsens = float(re.search(r"\\@Sens. Zsens: V ([0-9.eE+-]+) nm/V", text).group(1))
    return data[::-1].astype(np.float64) * (hard / 65536 * zsens * 1e-9)


# --- Sensofar PLU (plu-1.plu) -------------------------------------------------------------

def write_plu(path, n, rng):
    """The real file's 500-byte header (date, calibration, topography type 3; one layer, no
    colour image), then the layer: u32 rows, u32 cols, rows × cols f32 heights in µm, f32
    min and max. Heights: the f32 values times 1e-6, rows as stored."""
    head = bytearray(real("plu-1.plu")[:500])
    head[388:396] = struct.pack("<II", n, n)
    head[489] = 1
    head[492] = 0
    um = (rng.standard_normal((n, n)) * 2.0).astype("<f4")
    with open(path, "wb") as f:
        f.write(head)
        f.write(struct.pack("<II", n, n))
        f.write(um.tobytes())
        f.write(struct.pack("<ff", um.min(), um.max()))
    return um.astype(np.float64) * 1e-6


# --- Zygo MetroPro .dat (metropro-1.dat: header format 1, 834 bytes) -----------------------

def write_metropro(path, n, rng):
    """The real file's 834-byte header with the intensity frame (`ac_width`, `ac_height`,
    one bucket: n × n u16 zeros) and the phase map (`cn_width`, `cn_height`) set to n × n;
    big-endian i32 phases. Heights: phase · intf_scale_factor · obliquity · wavelength / R
    (R from `phase_res`), negated where `sign` is set; rows as stored."""
    head = bytearray(real("metropro-1.dat")[:834])
    head[52:58] = struct.pack(">HHH", n, n, 1)
    head[68:72] = struct.pack(">HH", n, n)
    scale, wavelength = struct.unpack(">ff", head[164:172])
    obliquity, = struct.unpack(">f", head[176:180])
    res = {0: 4096, 1: 32768, 2: 131072}[struct.unpack(">h", head[218:220])[0]]
    sign = -1.0 if struct.unpack(">h", head[232:234])[0] else 1.0
    phase = ints(rng, n, -200000, 200000, ">i4")
    with open(path, "wb") as f:
        f.write(head)
        f.write(bytes(2 * n * n))
        f.write(phase.tobytes())
    factor = sign * float(scale) * float(obliquity) * float(wavelength) / res
    return phase.astype(np.float64) * factor


# --- Bruker Dektak OPDx (opdx-3.opdx is a profile: the map is written in the layout) -------

def _opdx_named(text):
    b = text.encode("utf-8")
    return struct.pack("<I", len(b)) + b


def _opdx_item(name, kind, body):
    return _opdx_named(name) + bytes([kind]) + body


def _opdx_sized(body):
    return b"\x04" + struct.pack("<I", len(body)) + body


def _opdx_container(name, items):
    inner = b"".join(items) + _opdx_item("", 0x7F, b"") + b"\xff\xff"
    return _opdx_item(name, 0x7D, _opdx_sized(inner))


def _opdx_unit(name, value, symbol):
    body = _opdx_named("u") + _opdx_named(symbol) + struct.pack("<d", value) + bytes(12)
    return _opdx_item(name, 0x18, _opdx_sized(body))


def write_opdx(path, n, rng):
    """The `VCA DATA` signature, then the items of a map as asperity's reader (after
    SurfaceTopography's and Gwyddion's `dektakvca.c`) reads them: `/MetaData` (`DataKind`
    "Surface Height", the 2D channel list), `/2D_Data/Height` (`Dimension1Points` (y),
    `Dimension2Points` (x), their extents (first to last point) in µm, `DataScale` 1 µm,
    `Matrix`: y, x, then y rows of x little-endian f32). The real file of the shared
    folders is a profile, so no real header holds a map. Heights: f32 · 1e-6, rows as
    stored."""
    um = (rng.standard_normal((n, n)) * 2.0).astype("<f4")
    extent = 1000.0 * (n - 1) / n
    matrix = (_opdx_named("Matrix<float>")
              + _opdx_sized(struct.pack("<II", n, n) + um.tobytes()))
    channels = _opdx_named("StringList") + _opdx_sized(_opdx_named("Height"))
    data = _opdx_container("Height", [
        _opdx_item("DataKind", 0x12, b"\x01\x06Height"),
        _opdx_item("Dimension1Points", 0x07, struct.pack("<I", n)),
        _opdx_item("Dimension2Points", 0x07, struct.pack("<I", n)),
        _opdx_unit("Dimension1Extent", extent, "µm"),
        _opdx_unit("Dimension2Extent", extent, "µm"),
        _opdx_unit("DataScale", 1.0, "µm"),
        _opdx_item("Matrix", 0x45, matrix)])
    meta = _opdx_container("MetaData", [
        _opdx_item("DataKind", 0x12, b"\x01\x0eSurface Height"),
        _opdx_container("2D_Channels", [_opdx_item("Height", 0x42, channels)])])
    with open(path, "wb") as f:
        f.write(b"VCA DATA\x01\x00\x00\x55")
        f.write(meta + _opdx_container("2D_Data", [data]) + _opdx_item("", 0x7F, b"\xff\xff"))
    return um.astype(np.float64) * 1e-6


# --- Nanosurf NID (nid-1.nid: 2 groups × 4 channels of 256², 32-bit) ----------------------

def write_nid(path, n, rng):
    """The real file's header with its `[DataSet]` index cut to one channel, the forward
    scan's `Z-Axis` (`[DataSet-0:1]`, heights in m), whose `Points` and `Lines` are set to
    n; its n × n little-endian i32 samples after `#!`. Heights: Dim2Min + Dim2Range ·
    (s + 2³¹) / 2³², the lines stored from the bottom up (asperity's row 0 is the last
    line stored)."""
    b = real("nid-1.nid")
    text = b[:b.find(b"#!")].decode("latin1")
    index, rest = text.split("\r\n\r\n", 1)
    lines = [ln for ln in index.split("\r\n")
             if not re.match(r"Gr\d+-(Ch|Name|ID|Count)", ln) and not ln.startswith("GroupCount")]
    lines[1:1] = ["GroupCount=1", "Gr0-Name=Scan forward", "Gr0-ID=0", "Gr0-Count=8",
                  "Gr0-Ch1=DataSet-0:1"]
    start = rest.index("[DataSet-0:1]")
    end = rest.index("\r\n\r\n", start)
    section = rest[start:end]
    section = re.sub(r"\r\nPoints=\d+", f"\r\nPoints={n}", section)
    section = re.sub(r"\r\nLines=\d+", f"\r\nLines={n}", section)
    lo = float(re.search(r"Dim2Min=(\S+)", section).group(1))
    rng_ = float(re.search(r"Dim2Range=(\S+)", section).group(1))
    text = "\r\n".join(lines) + "\r\n\r\n" + rest[:start] + section + rest[end:]
    data = ints(rng, n, -2**31, 2**31, "<i4")
    with open(path, "wb") as f:
        f.write(text.encode("latin1"))
        f.write(b"#!")
        f.write(data.tobytes())
    return (lo + rng_ * (data[::-1].astype(np.float64) + 2**31) / 2**32)


# --- Igor binary wave, version 5 (spot_1-1000nm.ibw: Asylum, 256² × 8 f32 layers) --------

def write_ibw(path, n, rng):
    """The real file's BinHeader5 and WaveHeader5 (384 bytes) with `npnts`, `nDim` (n, n,
    one layer) and the wave record's size set, the steps `sfA` scaled so the sides keep
    their length, the checksum made again (the 16-bit words of the 384 bytes sum to 0);
    then n × n little-endian f32 heights (x fastest), the real file's note and the first
    two labels of its layer block (the dimension's own and the first layer's).
    Heights: the f32 values (data unit m), the lines stored from the bottom up."""
    b = real("spot_1-1000nm.ibw")
    head = bytearray(b[:384])
    wave, formula, note = struct.unpack("<iii", head[4:16])
    labels = struct.unpack("<4i", head[32:48])
    old = struct.unpack("<4i", head[132:148])
    steps = struct.unpack("<4d", head[148:180])
    note_bytes = b[64 + wave + formula:64 + wave + formula + note]
    label_at = 64 + wave + formula + note + sum(struct.unpack("<5i", head[16:36]))
    layer_labels = b[label_at + labels[0] + labels[1]:][:64]
    head[4:8] = struct.pack("<i", 320 + 4 * n * n)
    head[32:48] = struct.pack("<4i", 0, 0, 64, 0)
    head[64 + 12:64 + 16] = struct.pack("<i", n * n)
    head[132:148] = struct.pack("<4i", n, n, 1, 0)
    head[148:164] = struct.pack("<2d", steps[0] * old[0] / n, steps[1] * old[1] / n)
    head[2:4] = b"\0\0"
    total = sum(struct.unpack("<192H", bytes(head))) & 0xFFFF
    head[2:4] = struct.pack("<H", (-total) & 0xFFFF)
    z = (rng.standard_normal((n, n)) * 1e-7).astype("<f4")
    with open(path, "wb") as f:
        f.write(head)
        f.write(z.tobytes())
        f.write(note_bytes)
        f.write(layer_labels)
    return z[::-1].astype(np.float64)


# --- Alicona AL3D (al3d-1.al3d: 200 × 296, 4 texture planes) -------------------------------

def write_al3d(path, n, rng):
    """The real file's signature and tags (20-byte key, 30-byte value, CR LF) with `Cols`,
    `Rows` set to n and `TextureImageOffset` moved past the depth image, which stays at
    the real file's `DepthImageOffset`; n rows of n little-endian f32 heights in metres
    (4n bytes: a multiple of 8), then the texture planes (`NumberOfPlanes` × n × n bytes,
    zeros). Heights: the f32 values, rows as stored."""
    b = real("al3d-1.al3d")
    count = int(b[17 + 52 + 20:17 + 52 + 50].rstrip(b"\0"))
    tags = []
    for k in range(count + 2):
        at = 17 + 52 * k
        tags.append([b[at:at + 20].rstrip(b"\0"), b[at + 20:at + 50].rstrip(b"\0")])
    value = dict(tags)
    depth = int(value[b"DepthImageOffset"])
    planes = int(value[b"NumberOfPlanes"])
    new = {b"Cols": n, b"Rows": n, b"TextureImageOffset": depth + 4 * n * n}
    head = bytearray(b[:depth])
    for k, (key, _) in enumerate(tags):
        if key in new:
            at = 17 + 52 * k + 20
            head[at:at + 30] = str(new[key]).encode("ascii").ljust(30, b"\0")
    z = (rng.standard_normal((n, n)) * 1e-6).astype("<f4")
    with open(path, "wb") as f:
        f.write(head)
        f.write(z.tobytes())
        f.write(bytes(planes * n * n))
    return z.astype(np.float64)


# --- Keyence VK4 and VK6 (no real file in the shared folders: written in the layout) ------

def _vk4(n, rng):
    """A VK4 file: `VK4_`, version, file type 0, the 18-offset table, 304 bytes of
    measurement conditions (pixel sizes x, y and the height per count, in pm, at fields
    42–44), a 16-bit light image, then a 32-bit height image (each: width, height, depth,
    compression 0, byte size, palette range, a 768-byte palette, the samples along x
    fastest). Returns the bytes and the heights (counts × pm per count, in metres)."""
    conditions = 12 + 72
    light_at = conditions + 304
    height_at = light_at + 28 + 768 + 2 * n * n
    table = [0] * 18
    table[3], table[6] = light_at, height_at
    conds = [0] * 76
    conds[0] = 304
    conds[42], conds[43], conds[44] = 250_000, 250_000, 1_000  # pm
    counts = ints(rng, n, 0, 4_000_000, "<u4")

    def image(depth, data):
        return struct.pack("<7I", n, n, depth, 0, n * n * depth // 8, 0, 0) + bytes(768) + data

    body = (b"VK4_\x01\x00\x00\x00\0\0\0\0" + struct.pack("<18I", *table)
            + struct.pack("<76I", *conds)
            + image(16, ints(rng, n, 0, 65536, "<u2").tobytes()) + image(32, counts.tobytes()))
    return body, counts.astype(np.float64) * 1_000 * 1e-12


def write_vk4(path, n, rng):
    body, heights = _vk4(n, rng)
    with open(path, "wb") as f:
        f.write(body)
    return heights


def write_vk6(path, n, rng):
    """A VK6 container: `VK6` and 21 header bytes (zeros), then a zip archive whose
    deflated member `Vk4File` is a VK4 file as `write_vk4` makes it."""
    import io
    import zipfile
    body, heights = _vk4(n, rng)
    archive = io.BytesIO()
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("Vk4File", body)
    with open(path, "wb") as f:
        f.write(b"VK6" + bytes(21))
        f.write(archive.getvalue())
    return heights


# --- Keyence ZON (no real file: written in the layout SurfaceTopography's ZON.py reads) ---

ZON_HEIGHTS = "4cdb0c75-5706-48cc-a9a1-adf395d609ae"
ZON_UNITS = "686613b8-27b5-4a29-8ffc-438c2780873e"
ZON_VALID = "9e7ca6dd-0e6a-4d7b-8986-f0a7b773c916"
ZON_DEVICE = "cbc1d39b-215f-4d56-a20e-cf8e5f570755"
ZON_SCAN = "1d35862b-3b48-4df2-9235-833ef590b043"


def write_zon(path, n, rng):
    """`KPK0`, a u32 length and a (small) BMP thumbnail, then a zip archive (deflated) of
    the members named by their UUIDs: the device and scan XML, the calibration XML
    (`XYCalibration/MeterPerPixel`, `ZCalibration/MeterPerUnit`), the heights (width,
    height, element size 4, row bytes as i32; n rows of n i32 counts) and the validity
    mask (the same header with element size 1; all points valid). Heights: count ·
    MeterPerUnit, rows as stored."""
    import io
    import zipfile
    per_unit = 1e-9
    counts = ints(rng, n, -2_000_000, 2_000_000, "<i4")
    units = ("<?xml version=\"1.0\"?><Calibration><XYCalibration><MeterPerPixel>2.5e-7"
             "</MeterPerPixel></XYCalibration><ZCalibration><MeterPerUnit>" + repr(per_unit)
             + "</MeterPerUnit></ZCalibration></Calibration>")
    device = ("<?xml version=\"1.0\"?><Device><DeviceModelName>VR-5000</DeviceModelName>"
              "<DeviceSerialId>0</DeviceSerialId></Device>")
    scan = ("<?xml version=\"1.0\"?><Scan><ScanDateTime>2026-11-28T00:00:00</ScanDateTime>"
            "</Scan>")
    archive = io.BytesIO()
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr(ZON_DEVICE, device)
        z.writestr(ZON_SCAN, scan)
        z.writestr(ZON_UNITS, units)
        z.writestr(ZON_HEIGHTS, struct.pack("<4i", n, n, 4, 4 * n) + counts.tobytes())
        z.writestr(ZON_VALID, struct.pack("<4i", n, n, 1, n) + bytes(n * n))
    bmp = b"BM" + bytes(52)
    with open(path, "wb") as f:
        f.write(b"KPK0" + struct.pack("<I", len(bmp)) + bmp)
        f.write(archive.getvalue())
    return counts.astype(np.float64) * per_unit


# --- TIFF (LEXT, Park Systems): a small writer of little-endian TIFF directories -----------

def tiff_file(ifds, order="<"):
    """A TIFF file (byte order `order`) of the directories `ifds`, each `(entries, chained)`:
    entries {tag: (type, count, payload bytes)} (a payload of more than 4 bytes goes after
    the directories; ("ifd", k) as payload is the offset of directory k, for sub-IFDs),
    the chained ones linked as pages in order."""
    sizes = [2 + 12 * len(e) + 4 for e, _ in ifds]
    offsets = [8 + sum(sizes[:k]) for k in range(len(ifds))]
    blob = bytearray()
    base = 8 + sum(sizes)
    chain = [k for k, (_, c) in enumerate(ifds) if c]
    magic = b"II*\0" if order == "<" else b"MM\0*"
    out = bytearray(magic + struct.pack(order + "I", offsets[chain[0]]))
    for k, (entries, chained) in enumerate(ifds):
        out += struct.pack(order + "H", len(entries))
        for tag in sorted(entries):
            kind, count, payload = entries[tag]
            if isinstance(payload, tuple):
                payload = struct.pack(order + "I", offsets[payload[1]])
            if len(payload) <= 4:
                value = payload.ljust(4, b"\0")
            else:
                value = struct.pack(order + "I", base + len(blob))
                blob += payload
                blob += b"\0" * (len(blob) % 2)
            out += struct.pack(order + "HHI", tag, kind, count) + value
        later = [j for j in chain if j > k] if chained else []
        out += struct.pack(order + "I", offsets[later[0]] if later else 0)
    return bytes(out + blob)


def _short(v):
    return (3, 1, struct.pack("<H", v))


def _long(v):
    return (4, 1, struct.pack("<I", v))


def _ascii(text):
    b = text.encode("ascii") + b"\0"
    return (2, len(b), b)


# --- Olympus LEXT (no real file: written in the layout) ------------------------------------

def write_lext(path, n, rng):
    """A TIFF of two pages: page 0 an n × n 8-bit overview (zeros) whose ImageDescription is
    the `TiffTagDescData` XML (`HeightInfo`: pm per pixel along x and y, pm per count along
    z) and whose EXIF directory's DeviceSettingDescription holds `MakerCalibrationValueX/
    Y/Z` (1, 1, 1.25); page 1 the `HEIGHT` raster of n × n u32 counts, one strip. Heights:
    count · HeightDataPerPixelZ · MakerCalibrationValueZ pm, rows as stored."""
    per_z, cal_z = 10.0, 1.25
    xml = ("<?xml version=\"1.0\"?><TiffTagDescData version=\"1\"><HeightInfo>"
           "<HeightDataPerPixelX>250000</HeightDataPerPixelX><HeightDataPerPixelY>250000"
           "</HeightDataPerPixelY><HeightDataPerPixelZ>10</HeightDataPerPixelZ>"
           "<HeightDataUnitX>1</HeightDataUnitX><HeightDataUnitY>1</HeightDataUnitY>"
           "<HeightDataUnitZ>1</HeightDataUnitZ></HeightInfo></TiffTagDescData>")
    setting = ("<?xml version=\"1.0\"?><ExifTagDescData><ImageCommonSettingsInfo>"
               "<MakerCalibrationValueX>1</MakerCalibrationValueX><MakerCalibrationValueY>1"
               "</MakerCalibrationValueY><MakerCalibrationValueZ>1.25</MakerCalibrationValueZ>"
               "</ImageCommonSettingsInfo></ExifTagDescData>").encode("ascii") + b"\0"
    counts = ints(rng, n, 0, 4_000_000, "<u4")
    overview = bytes(n * n)
    raster = counts.tobytes()
    first = {256: _long(n), 257: _long(n), 258: _short(8), 259: _short(1), 262: _short(1),
             270: _ascii(xml), 273: (4, 1, ("blob", overview)), 277: _short(1),
             278: _long(n), 279: _long(len(overview)), 34665: (4, 1, ("ifd", 2))}
    height = {256: _long(n), 257: _long(n), 258: _short(32), 259: _short(1), 262: _short(1),
              270: _ascii("HEIGHT"), 273: (4, 1, ("blob", raster)), 277: _short(1),
              278: _long(n), 279: _long(len(raster))}
    exif = {41995: (2, len(setting), setting)}  # ASCII, as SurfaceTopography needs it
    write_tiff_with_strips(path, [(first, True), (height, True), (exif, False)])
    return counts.astype(np.float64) * per_z * cal_z * 1e-12


def write_tiff_with_strips(path, ifds, order="<"):
    """`tiff_file`, with ("blob", bytes) strip payloads placed at the end of the file (the
    big rasters are not copied through the small blob)."""
    big = []
    end = [0]

    def resolve(entries):
        out = {}
        for tag, (kind, count, payload) in entries.items():
            if isinstance(payload, tuple) and payload[0] == "blob":
                big.append(payload[1])
                out[tag] = (kind, count, ("big", len(big) - 1))
            else:
                out[tag] = (kind, count, payload)
        return out

    ifds = [(resolve(e), c) for e, c in ifds]
    # First pass with placeholders to learn the head's length, then the real offsets.
    placeholder = [(dict((t, (k, c, struct.pack("<I", 0) if isinstance(p, tuple)
                                and p[0] == "big" else p)) for t, (k, c, p) in e.items()), ch)
                   for e, ch in ifds]
    head_len = len(tiff_file(placeholder, order))
    end[0] = head_len + (head_len % 2)
    at = []
    for b in big:
        at.append(end[0])
        end[0] += len(b)
    final = [(dict((t, (k, c, struct.pack(order + "I", at[p[1]]) if isinstance(p, tuple)
                         and p[0] == "big" else p)) for t, (k, c, p) in e.items()), ch)
             for e, ch in ifds]
    head = tiff_file(final, order)
    assert len(head) == head_len
    with open(path, "wb") as f:
        f.write(head)
        f.write(bytes(head_len % 2))
        for b in big:
            f.write(b)


# --- Bruker / Wyko OPD (opd-1.opd: 640 × 480 f32 `Raw`, an intensity array and an image) --

def write_opd(path, n, rng):
    """The real file's prelude and directory, each array block (type 3: `Raw`, `SecArr_0`,
    `Image`) resized to n × n of its own sample size (`Raw` the heights, the others
    zeros), every other block's payload as it is. Heights: f32 · Wavelength (nm), stored
    x-major ([x][y]), y reversed (asperity's row y is the stored column's sample
    n − 1 − y)."""
    b = real("opd-1.opd")
    length, = struct.unpack("<i", b[20:24])
    entries, payloads = [], []
    at = 2 + length
    for k in range(1, length // 24):
        e = bytearray(b[2 + 24 * k:2 + 24 * k + 24])
        kind, size = struct.unpack("<hi", e[16:22])
        size = max(size, 0)
        entries.append(e)
        payloads.append(b[at:at + size])
        at += size
    z = None
    for e, k in zip(entries, range(len(entries))):
        name = bytes(e[:16]).split(b"\0")[0]
        kind, = struct.unpack("<h", e[16:18])
        if kind != 3:
            continue
        width = struct.unpack("<3H", payloads[k][:6])[2]
        if name == b"Raw":
            assert width == 4
            z = (rng.standard_normal((n, n)) * 50.0).astype("<f4")  # [x][y]
            data = z.tobytes()
        else:
            data = bytes(width * n * n)
        payloads[k] = struct.pack("<3H", n, n, width) + data
        e[18:22] = struct.pack("<i", len(payloads[k]))
    wavelength = next(struct.unpack("<f", p[:4])[0] for e, p in zip(entries, payloads)
                      if bytes(e[:16]).split(b"\0")[0] == b"Wavelength")
    with open(path, "wb") as f:
        f.write(b[:2 + 24])
        for e in entries:
            f.write(e)
        for p_ in payloads:
            f.write(p_)
    return z.T[::-1].astype(np.float64) * float(wavelength) * 1e-9


# --- FRT MicroProf (frt-2.frt: version 1.00, 150 × 300 u16) ---------------------------------

def write_frt(path, n, rng):
    """The real file's blocks in order, with the grid block 0x66 set to n × n (16 bits),
    the topography block 0x0B n rows of n u16 samples, and the multi-image block 0x7D
    rebuilt with its images n × n (its topography image the same samples, the other
    zeros). Heights: sample · the metres per count of block 0x6C (a sample of 1 would be
    undefined: none is drawn), rows reversed (the first stored row is the bottom line)."""
    b = real("frt-2.frt")
    assert b[12:16] == b"1.00"
    count, = struct.unpack("<H", b[16:18])
    at = 18
    blocks = []
    for _ in range(count):
        tag, size = struct.unpack("<HI", b[at:at + 6])
        blocks.append((tag, b[at + 6:at + 6 + size]))
        at += 6 + size
    data = ints(rng, n, 2, 65536, "<u2")
    scale = None
    out = []
    for tag, payload in blocks:
        if tag == 0x66:
            payload = struct.pack("<3I", n, n, 16)
        elif tag == 0x0B:
            payload = data.tobytes()
        elif tag == 0x6C:
            scale, = struct.unpack("<d", payload[4:12])
        elif tag == 0x7D:
            multi = bytearray(payload[:8])
            c = 8
            while c < len(payload):
                kind, nx, ny, bits = struct.unpack("<4I", payload[c:c + 16])
                c += 16 + nx * ny * bits // 8
                multi += struct.pack("<4I", kind, n, n, 16)
                multi += data.tobytes() if kind == 0x4 else bytes(2 * n * n)
            payload = bytes(multi)
        out.append(struct.pack("<HI", tag, len(payload)) + payload)
    with open(path, "wb") as f:
        f.write(b[:18])
        for blk in out:
            f.write(blk)
    return data[::-1].astype(np.float64) * scale


# --- NanoFocus NMS (no real file in the shared folders: written in the layout) ------------

def write_nms(path, n, rng):
    """The 3468-byte header with its fields at their offsets (16, 24: the lowest and highest
    height in µm, f64; 32: `OM_MS_2.0`; 52: the title; 1352: the height block's offset
    3468, 1356: 2 bytes per height; 1368, 1372: the points along x and y; 1376, 1384: the
    steps, f64), n rows of n u16 counts, then an n × n 8-bit intensity image (zeros).
    Heights: zmin + count · (zmax − zmin) / 65534 µm, rows as stored. The file gives no
    size (asperity asks for one: the bench passes --size)."""
    zmin, zmax = -3.0, 5.0
    head = bytearray(3468)
    head[0:16] = struct.pack("<4I", 2, 1, 0, 65535)
    head[16:32] = struct.pack("<dd", zmin, zmax)
    head[32:41] = b"OM_MS_2.0"
    head[52:73] = b"Confocal Height Image"
    head[1352:1360] = struct.pack("<II", 3468, 2)
    head[1368:1392] = struct.pack("<IIdd", n, n, 312.5, 312.5)
    counts = ints(rng, n, 0, 65535, "<u2")
    with open(path, "wb") as f:
        f.write(head)
        f.write(counts.tobytes())
        f.write(bytes(n * n))
    return (zmin + counts.astype(np.float64) * ((zmax - zmin) / 65534)) * 1e-6


# --- WSxM (stp-1.stp: 256² doubles in nm) ----------------------------------------------------

def write_wsxm(path, n, rng):
    """The real file's text header with `Number of columns` and `Number of rows` set to n
    and `Image header size` made again (the header's length up to and with `[Header end]`
    and its line end), then n × n little-endian f64 heights in the `Z Amplitude`'s unit
    (nm). Heights: the values times 1e-9, the image rotated by 180° (both axes reversed)."""
    b = real("stp-1.stp")
    end = b.find(b"[Header end]") + len(b"[Header end]\r\n")
    text = b[:end].decode("latin1")
    text = re.sub(r"Number of columns: \d+", f"Number of columns: {n}", text)
    text = re.sub(r"Number of rows: \d+", f"Number of rows: {n}", text)
    for _ in range(3):  # the size's own digits count in the size
        text = re.sub(r"Image header size: \d+", f"Image header size: {len(text)}", text)
    assert f"Image header size: {len(text)}" in text
    nm = rng.standard_normal((n, n)) * 3.0
    with open(path, "wb") as f:
        f.write(text.encode("latin1"))
        f.write(nm.astype("<f8").tobytes())
    return nm[::-1, ::-1] * 1e-9


# --- JPK image scan (afmreader-sample_0.jpk: big-endian TIFF, 256² i32 channels) ------------

def _raw_tags(b, page, order):
    """{tag: (type, count, the value's bytes as stored)} of a tifffile page of the bytes b."""
    sizes = {1: 1, 2: 1, 3: 2, 4: 4, 5: 8, 6: 1, 7: 1, 8: 2, 9: 4, 10: 8, 11: 4, 12: 8, 16: 8}
    out = {}
    for code, tag in page.tags.items():
        kind = int(tag.dtype)
        length = sizes[kind] * tag.count
        at = tag.valueoffset if length > 4 else tag.offset + 8
        out[code] = (kind, tag.count, b[at:at + length])
    return out


def write_jpk(path, n, rng):
    """The real file's first page (its 64² thumbnail and the scan's global tags: grid
    lengths, …) and its first channel page (`Height`, retrace) with every private tag as
    stored (its slots: name, unit, scaling, multiplier, offset) and its raster n × n
    big-endian i32 in one strip; the other channel pages left out. Heights: (raw +
    offset / multiplier) · multiplier of the default slot, in its unit (m), the first line
    the bottom of the image (rows reversed; no GridReflect)."""
    import tifffile
    b = real("afmreader-sample_0.jpk")
    order = ">"
    with tifffile.TiffFile(os.path.join(SHARED, "topographies-3",
                                        "afmreader-sample_0.jpk")) as t:
        pages = [_raw_tags(b, t.pages[k], order) for k in (0, 1)]
        thumb = b[t.pages[0].dataoffsets[0]:][:sum(t.pages[0].databytecounts)]
        tags = {code: tag.value for code, tag in t.pages[1].tags.items()}
    raw = ints(rng, n, -2**30, 2**30, ">i4")
    first, height = pages
    first[273] = (4, 1, ("blob", thumb))
    first[279] = (4, 1, struct.pack(">I", len(thumb)))
    first[278] = (4, 1, struct.pack(">I", 64))
    data = raw.tobytes()
    height.update({256: (4, 1, struct.pack(">I", n)), 257: (4, 1, struct.pack(">I", n)),
                   273: (4, 1, ("blob", data)), 278: (4, 1, struct.pack(">I", n)),
                   279: (4, 1, struct.pack(">I", len(data)))})
    write_tiff_with_strips(path, [(first, True), (height, True)], order)
    default = tags[0x8081]
    base = next(0x8090 + k * 0x30 for k in range(int(tags[0x8080]))
                if tags[0x8090 + k * 0x30] == default)
    assert tags[base + 0x12] == "m" and tags[base + 0x13] == "LinearScaling"
    multiply, offset = float(tags[base + 0x14]), float(tags[base + 0x15])
    return ((raw.astype(np.float64) + offset / multiply) * multiply)[::-1]


# --- Park Systems TIFF (no real file in the shared folders: written in the layout) ---------

def write_park(path, n, rng):
    """A one-page little-endian TIFF: a 256² 8-bit preview (zeros) and Park's private tags:
    50432 the magic 0x0E031301, 50433 version 2 (0x01000002), 50434 the data block (n × n
    f32, line by line), 50435 the packed 580-byte header (image type 0, source name
    `Z Height` in UTF-16LE, points along x and y, scan sizes in µm, gain 2, scale 0.5,
    offset 1, unit `nm`, compression 0, sample type 2 = f32). Heights: gain · (scale · raw
    + offset) nm, the first line at the bottom (rows reversed)."""
    gain, scale, offset = 2.0, 0.5, 1.0
    head = bytearray(580)
    head[0:4] = struct.pack("<I", 0)
    name = "Z Height".encode("utf-16-le")
    head[4:4 + len(name)] = name
    head[100:108] = struct.pack("<II", n, n)
    head[140:156] = struct.pack("<dd", 1000.0, 1000.0)
    head[220:244] = struct.pack("<ddd", gain, scale, offset)
    unit = "nm".encode("utf-16-le")
    head[244:244 + len(unit)] = unit
    head[272:276] = struct.pack("<I", 0)
    head[348:352] = struct.pack("<I", 2)
    raw = (rng.standard_normal((n, n)) * 5.0).astype("<f4")
    data = raw.tobytes()
    preview = bytes(256 * 256)
    page = {256: _long(256), 257: _long(256), 258: _short(8), 259: _short(1), 262: _short(1),
            273: (4, 1, ("blob", preview)), 277: _short(1), 278: _long(256),
            279: _long(len(preview)), 50432: _long(0x0E031301), 50433: _long(0x01000002),
            50434: (1, len(data), ("blob", data)), 50435: (7, len(head), bytes(head))}
    write_tiff_with_strips(path, [(page, True)])
    return (gain * (scale * raw.astype(np.float64) + offset) * 1e-9)[::-1]


# --- MountainsMap .mnt (mnt-1.mnt: an OLE document, 960 × 600 i32 heights in zlib blocks) --

def _mnt_entries(data, prefixed=False):
    """[prefix, tag, data] of a container of ScopedContents' tag-size-data tree."""
    out, pos, head = [], 0, 18 if prefixed else 10
    while pos < len(data):
        at = pos + head - 10
        tag, size = struct.unpack("<HQ", data[at:at + 10])
        out.append([data[pos:at], tag, data[pos + head:pos + head + size]])
        pos += head + size
    return out


def _mnt_pack(entries):
    return b"".join(p + struct.pack("<HQ", t, len(d)) + d for p, t, d in entries)


def _mnt_child(data, tag):
    return next(d for _, t, d in _mnt_entries(data) if t == tag)


def _mnt_edit(data, path, fn, prefixed=False):
    """`data` with the first entry along `path` (tags) replaced by fn(its data)."""
    entries = _mnt_entries(data, prefixed)
    for e in entries:
        if e[1] == path[0]:
            e[2] = fn(e[2]) if len(path) == 1 else _mnt_edit(e[2], path[1:], fn)
            return _mnt_pack(entries)
    raise KeyError(path)


def _mnt_text(data):
    return data[1:].decode("utf-16-le").rstrip("\0")


def _ole_v4(streams):
    """An OLE compound document, version 4 (4096-byte sectors), of the root streams
    {name: bytes}, each at least 4096 bytes (so none goes to the mini stream): sector 0 the
    directory, then the FAT sectors, then each stream's sectors in a row."""
    sector, free, end, fat_mark = 4096, 0xFFFFFFFF, 0xFFFFFFFE, 0xFFFFFFFD
    names = sorted(streams, key=lambda k: (len(k), k.upper()))
    counts = [-(-len(streams[k]) // sector) for k in names]
    fat_n = 1
    while 1 + fat_n + sum(counts) > 1024 * fat_n:
        fat_n += 1
    assert fat_n <= 109
    fat = [end] + [fat_mark] * fat_n
    starts = []
    for c in counts:
        starts.append(len(fat))
        fat += list(range(len(fat) + 1, len(fat) + c)) + [end]
    fat += [free] * (1024 * fat_n - len(fat))

    def entry(name, kind, color, left, right, child, start, size):
        raw = (name + "\0").encode("utf-16-le")
        return (raw.ljust(64, b"\0") + struct.pack("<HBBIII", len(raw), kind, color, left,
                                                      right, child)
                + bytes(16) + struct.pack("<IQQIQ", 0, 0, 0, start, size))

    # A red-black tree of the streams: the first black, each next one its red right child
    # (valid for two streams, the case here).
    assert len(names) <= 2
    dirs = [entry("Root Entry", 5, 1, free, free, 1, end, 0)]
    for k, name in enumerate(names):
        right = k + 2 if k + 1 < len(names) else free
        dirs.append(entry(name, 2, 1 if k == 0 else 0, free, right, free, starts[k],
                          len(streams[name])))
    directory = b"".join(dirs) + entry("", 0, 0, free, free, free, 0, 0) * (32 - len(dirs))
    difat = list(range(1, 1 + fat_n)) + [free] * (109 - fat_n)
    header = (b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1" + bytes(16)
              + struct.pack("<HHHHH", 0x3E, 4, 0xFFFE, 12, 6) + bytes(6)
              + struct.pack("<IIIIIIIII", 1, fat_n, 0, 0, 4096, end, 0, end, 0)
              + struct.pack("<109I", *difat))
    out = [header.ljust(sector, b"\0"), directory, struct.pack(f"<{len(fat)}I", *fat)]
    for name in names:
        data = streams[name]
        out.append(data + bytes(-len(data) % sector))
    return out


def write_mnt(path, n, rng):
    """The real file's ScopedContents with the measured surface (its class-9012 object)
    made n × n: both axes' point counts set to n (steps kept), the heights array's count
    set to n², its data n² i32 counts in zlib blocks of the real file's block length; every
    container's size along that path made again, and the stream's own leading length. The
    document is written again as an OLE file (version 4, as the real one) holding
    ScopedContents and the real ImagePreview. Heights: (count · step + origin) in the
    height axis's display unit, rows as stored (x fastest)."""
    import zlib
    import olefile
    ole = olefile.OleFileIO(os.path.join(SHARED, "topographies-2", "mnt-1.mnt"))
    contents = ole.openstream("ScopedContents").read()
    preview = ole.openstream("ImagePreview").read()
    counts = ints(rng, n, -2**24, 2**24, "<i4")
    body = contents[8:]
    objects = _mnt_child(_mnt_child(_mnt_child(_mnt_child(body, 1), 0x2BD), 2), 1)
    entries = _mnt_entries(objects, prefixed=True)
    k = next(i for i, (_, _, d) in enumerate(entries)
             if struct.unpack("<I", _mnt_child(_mnt_child(d, 1), 1))[0] == 9012)
    surface = entries[k][2]
    m_path = [2, 1, 2, 0xFFFF]
    m = surface
    for t in m_path:
        m = _mnt_child(m, t)
    z_scale = _mnt_child(_mnt_child(m, 2), 0xFFFF)
    step, = struct.unpack("<d", _mnt_child(z_scale, 1))
    unit = _mnt_text(_mnt_child(z_scale, 2))
    shown = _mnt_text(_mnt_child(z_scale, 3))
    origin, = struct.unpack("<d", _mnt_child(z_scale, 5))
    metres = {"m": 1.0, "mm": 1e-3, "µm": 1e-6, "nm": 1e-9}
    old = _mnt_child(_mnt_child(_mnt_child(m, 1), 2), 2)
    per_block = struct.unpack("<QII", old[8:24])[1]
    flat = counts.reshape(-1)
    blocks = [struct.pack("<Q", 4 * n * n)]
    for at in range(0, n * n, per_block):
        part = flat[at:at + per_block]
        packed = zlib.compress(part.tobytes(), 1)
        blocks.append(struct.pack("<QII", at, len(part), len(packed)) + packed)
    array = b"".join(blocks)
    u32 = struct.pack("<I", n)
    for axis in (1, 2):
        surface = _mnt_edit(surface, m_path + [0xFFFF, axis, 0xFFFF, 1], lambda _: u32)
    surface = _mnt_edit(surface, m_path + [1, 2, 1], lambda _: struct.pack("<I", n * n))
    surface = _mnt_edit(surface, m_path + [1, 2, 2], lambda _: array)
    entries[k][2] = surface
    objects = _mnt_pack(entries)
    body = _mnt_edit(body, [1, 0x2BD, 2, 1], lambda _: objects)
    parts = _ole_v4({"ScopedContents": struct.pack("<Q", len(body)) + body,
                     "ImagePreview": preview})
    with open(path, "wb") as f:
        for part in parts:
            f.write(part)
    return (flat.astype(np.float64) * step * (metres[unit] / metres[shown]) + origin).reshape(
        n, n) * metres[shown]


WRITERS = {"di": write_di, "plu": write_plu, "metropro": write_metropro, "opdx": write_opdx,
           "nid": write_nid, "ibw": write_ibw, "al3d": write_al3d,
           "vk4": write_vk4, "vk6": write_vk6,
           "zon": write_zon, "lext": write_lext, "opd": write_opd, "frt": write_frt,
           "nms": write_nms, "wsxm": write_wsxm, "jpk": write_jpk,
           "park": write_park, "mnt": write_mnt}
SUFFIX = {"metropro": "dat", "wsxm": "stp", "park": "tiff"}
