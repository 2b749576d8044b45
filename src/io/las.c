/*
 * las.c -- ASPRS LAS 1.0 to 1.4, uncompressed, point data formats 0-10.
 *
 * Format (ASPRS "LAS Specification 1.4 - R15", 2019, section 2.4 Public
 * Header Block; earlier versions are prefixes of it): "LASF"; at byte 24
 * the version major/minor; at 94 the header size (u16), at 96 the offset to
 * point data (u32), at 104 the point data format (u8) and at 105 the record
 * length (u16), at 107 the legacy point count (u32), at 131 the x/y/z scale
 * factors and at 155 the x/y/z offsets (f64), and in 1.4 (header >= 375
 * bytes) at 247 the 64-bit point count.  Every point format starts with X,
 * Y, Z as little-endian int32; the coordinate is X * scale + offset,
 * evaluated in double exactly in that order (no fused multiply-add), which
 * is how the bundled haystack_rock.ply was made.
 *
 * Checks before anything is allocated: the header and the point offset lie
 * inside the file; the record length is at least the format's minimum
 * (20 28 26 34 57 63 30 36 38 59 67 bytes for formats 0-10; extra bytes are
 * skipped); count * record length fits between the point offset and the
 * end of the file, and the bytes after them are the waveform data or
 * extended VLRs the header points to, else the count is wrong (an error,
 * never a silent partial read; a 1.4 legacy count that disagrees with the
 * 64-bit count is refused too); scales and offsets are finite.  A compressed (LAZ) file,
 * recognised by bit 7 of the format byte as LASzip sets it, goes to laz.c
 * once the header is checked (its record length and count describe the
 * points before compression); one whose format byte lost that bit fails
 * the size checks, and their message then names its LASzip VLR.  Points are converted in parallel from the
 * mapping (hd__binary_read).
 */
#include "io.h"

#include <math.h>

static const unsigned char min_record[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

static double f64_at(const unsigned char *p) {
    uint64_t u = hd__ld_u64(p, 0);
    double v;
    memcpy(&v, &u, sizeof v);
    return v;
}

int hd__read_las(hd__read_t *r) {
    const unsigned char *d = r->f->data;
    size_t size = r->f->size;
    if (size < 4 || memcmp(d, "LASF", 4) != 0)
        return hd__io_err_at(r, HD_EFORMAT, 0, "not a LAS file (it does not start with 'LASF')");
    if (size < 227)
        return hd__io_err_at(r, HD_EFORMAT, (long long)size, "file ends inside the LAS header (227 bytes at least)");
    unsigned major = d[24], minor = d[25];
    if (major != 1 || minor > 4)
        return hd__io_err_at(r, HD_EUNSUPPORTED, 24, "LAS version %u.%u (1.0 to 1.4 are read)", major, minor);
    size_t header = hd__ld_u16(d + 94, 0);
    size_t offset = hd__ld_u32(d + 96, 0);
    unsigned fmt_byte = d[104];
    size_t rec = hd__ld_u16(d + 105, 0);
    uint64_t count = hd__ld_u32(d + 107, 0);
    if (header < 227 || header > size)
        return hd__io_err_at(r, HD_EFORMAT, 94, "header size %zu (at least 227, at most the file's %zu bytes)", header, size);
    unsigned fmt = fmt_byte & 0x3f;
    if (fmt > 10)
        return hd__io_err_at(r, HD_EUNSUPPORTED, 104, "point data format %u (0 to 10 are defined)", fmt);
    if (rec < min_record[fmt])
        return hd__io_err_at(r, HD_EFORMAT, 105, "record length %zu is shorter than point format %u's %u bytes", rec, fmt,
                             min_record[fmt]);
    if (minor >= 4 && header >= 375) {
        uint64_t c64 = hd__ld_u64(d + 247, 0);
        if (c64 != 0 && count != 0 && c64 != count)
            return hd__io_err_at(r, HD_EFORMAT, 107, "the legacy point count %llu disagrees with the 64-bit count %llu",
                                 (unsigned long long)count, (unsigned long long)c64);
        if (c64 != 0 || count == 0) count = c64;
    }
    if (offset < header || offset > size)
        return hd__io_err_at(r, HD_EFORMAT, 96, "offset to point data %zu is outside [header size %zu, file size %zu]", offset,
                             header, size);
    double scale[3], shift[3];
    for (int c = 0; c < 3; c++) {
        scale[c] = f64_at(d + 131 + 8 * c);
        shift[c] = f64_at(d + 155 + 8 * c);
        if (!isfinite(scale[c]) || !isfinite(shift[c]))
            return hd__io_err_at(r, HD_EFORMAT, (long long)(isfinite(scale[c]) ? 155 + 8 * c : 131 + 8 * c),
                                 "%c %s is not a finite number", "xyz"[c], isfinite(scale[c]) ? "offset" : "scale factor");
    }
    uint64_t evlr_at = minor >= 4 && header >= 247 && hd__ld_u32(d + 243, 0) > 0 ? hd__ld_u64(d + 235, 0) : 0;
    hd__las_header_t h = {minor, fmt, header, offset, rec, count, hd__ld_u32(d + 100, 0), evlr_at, {0}, {0}};
    memcpy(h.scale, scale, sizeof scale);
    memcpy(h.shift, shift, sizeof shift);
    if (fmt_byte & 0x80) return hd__read_laz(r, &h);
    /* a LAZ file whose format byte lost bit 7 fails the size checks below:
     * their messages say so */
    const char *laz = hd__laz_vlr_present(d, &h) ? "; the file has a LASzip VLR (user 'laszip encoded', record 22204), so its "
                                                   "points are compressed: the point format byte (104) lacks its compression bit 7"
                                                 : "";
    if (count > (size - offset) / rec)
        return hd__io_err_at(r, HD_EFORMAT, (long long)size,
                             "file ends inside the points: %llu of %zu bytes declared, room for %zu%s",
                             (unsigned long long)count, rec, (size - offset) / rec, laz);
    /* What follows the points must be accounted for by the header: the
     * waveform data (1.3) or the extended VLRs (1.4) start there.  Other
     * bytes mean the count is lower than the data: never a silent partial
     * read. */
    size_t end = offset + (size_t)count * rec;
    if (end < size) {
        uint64_t wave = minor >= 3 && header >= 235 ? hd__ld_u64(d + 227, 0) : 0;
        uint64_t evlr = minor >= 4 && header >= 247 ? hd__ld_u64(d + 235, 0) : 0;
        uint32_t n_evlr = minor >= 4 && header >= 247 ? hd__ld_u32(d + 243, 0) : 0;
        int explained = (wave >= end && wave < size) || (n_evlr > 0 && evlr >= end && evlr < size);
        if (!explained)
            return hd__io_err_at(r, HD_EFORMAT, (long long)end,
                                 "%zu bytes after the %llu declared points (%zu bytes each), and the header names "
                                 "nothing that follows them: the point count is wrong%s",
                                 size - end, (unsigned long long)count, rec, laz);
    }
    hd__layout_t L = {(size_t)count, 1, rec, 0, {0, 4, 8}, {HD__T_I32, HD__T_I32, HD__T_I32}, 0, scale, shift, offset};
    return hd__binary_read(r, d + offset, &L);
}
