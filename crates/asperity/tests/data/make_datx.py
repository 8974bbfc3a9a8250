"""Writes the two Zygo .datx test files of asperity's datx reader (h5py; run from this folder).

No real .datx file was at hand: these follow the layout that SurfaceTopography 1.27.1's
DATXReader and Gwyddion read (learned from their readers, not copied): a root dataset
`MetaData`, a table of (Source, Link, Destination) strings that leads Root -> Measurement ->
Surface -> Path; the surface dataset stored (rows, columns) = (y, x) with attributes `Unit`,
`No Data` and the compound `X/Y/Z Converter` (Category, BaseUnit, Unit, Parameters; the lateral
spacing in metres is Parameters[1]). `datx-vlen.datx` uses variable-length strings and
parameter arrays (h5py's default for str), `datx-fixed.datx` fixed-length ones, the two ways a
writer may store them.

Heights: z[r, c] = 10 * r + c - 7.5 in the file's unit (nm, resp. µm), the point (1, 2) is
the `No Data` value, and (2, 3) NaN; 4 rows (y) and 5 columns (x); spacing x 0.25 µm, y 0.5 µm.
"""
import h5py
import numpy as np

ROWS, COLS = 4, 5
DX, DY = 0.25e-6, 0.5e-6
NO_DATA = 1.7976931348623157e308


def heights():
    z = np.fromfunction(lambda r, c: 10.0 * r + c - 7.5, (ROWS, COLS))
    z[1, 2] = NO_DATA
    z[2, 3] = np.nan
    return z


def write(name, unit, vlen):
    if vlen:
        text = h5py.string_dtype('utf-8')
        params = h5py.vlen_dtype(np.float64)
    else:
        text = 'S64'
        params = ('<f8', (4,))
    conv = np.dtype([('Category', text), ('BaseUnit', text), ('Unit', text),
                     ('Parameters', params)])
    meta = np.dtype([('Source', text), ('Link', text), ('Destination', text)])
    guid = '{5AD3C1B8-0000-4000-8000-00000000A5E1}'
    with h5py.File(name, 'w') as f:
        rows = [('Root', 'Measurement', '{M}'), ('{M}', 'Surface', '{S}'),
                ('{S}', 'Path', f'/Measurement/Surface/{guid}'),
                ('{M}', 'Intensity', '{I}'), ('{I}', 'Path', '/Measurement/Intensity')]
        table = np.empty(len(rows), dtype=meta)
        for i, r in enumerate(rows):
            table[i] = tuple(s if vlen else s.encode() for s in r)
        f.create_dataset('MetaData', data=table)
        ds = f.create_dataset(f'Measurement/Surface/{guid}', data=heights())
        ds.attrs['Unit'] = np.array([unit if vlen else unit.encode()], dtype=text)
        ds.attrs['No Data'] = np.array([NO_DATA])

        def converter(category, base, unit, values):
            c = np.empty(1, dtype=conv)
            s = (lambda x: x) if vlen else (lambda x: x.encode())
            c[0] = (s(category), s(base), s(unit),
                    np.array(values) if vlen else tuple(values))
            return c
        ds.attrs['X Converter'] = converter('LateralCat', 'Pixels', 'Meters', [0, DX, 0, 0])
        ds.attrs['Y Converter'] = converter('LateralCat', 'Pixels', 'Meters', [0, DY, 0, 0])
        ds.attrs['Z Converter'] = converter('HeightCat', unit, unit, [0, 1, 0, 0])
        f.create_dataset('Measurement/Intensity', data=np.ones((ROWS, COLS)))


write('datx-vlen.datx', 'NanoMeters', True)
write('datx-fixed.datx', 'MicroMeters', False)
