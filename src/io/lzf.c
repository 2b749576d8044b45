/*
 * lzf.c -- decompression of LZF (Marc Lehmann's liblzf format), which PCL
 * uses for PCD "binary_compressed" data.
 *
 * The stream is a sequence of commands, each opening with a control byte c:
 *   c < 32       a literal run: the next c + 1 input bytes are copied out;
 *   c >= 32      a back reference of length L = c >> 5 (if L == 7, the next
 *                byte is added to it), then an offset byte b: copy L + 2
 *                bytes from (output position - ((c & 31) << 8) - b - 1),
 *                byte by byte, so overlapping copies repeat a pattern.
 * This decoder is written from that description (it shares no code with
 * liblzf) and trusts nothing: every literal is checked against the input
 * left, every reference against the output produced so far, and every copy
 * against the output room, so a corrupt or hostile stream gives an error
 * with the input offset where it went wrong, never a read or write out of
 * bounds.  The output must come out exactly out_len bytes long.
 */
#include "io.h"

int hd__lzf_decompress(const unsigned char *in, size_t in_len, unsigned char *out,
                       size_t out_len, size_t *bad_at) {
    size_t ip = 0, op = 0;
    while (ip < in_len) {
        size_t at = ip;
        unsigned c = in[ip++];
        if (c < 32) {
            size_t n = (size_t)c + 1;
            if (n > in_len - ip || n > out_len - op) {
                *bad_at = at;
                return -1;
            }
            memcpy(out + op, in + ip, n);
            ip += n;
            op += n;
            continue;
        }
        size_t len = c >> 5;
        if (len == 7) {
            if (ip >= in_len) {
                *bad_at = at;
                return -1;
            }
            len += in[ip++];
        }
        if (ip >= in_len) {
            *bad_at = at;
            return -1;
        }
        size_t back = ((size_t)(c & 31) << 8) + in[ip++] + 1;
        len += 2;
        if (back > op || len > out_len - op) {
            *bad_at = at;
            return -1;
        }
        const unsigned char *ref = out + op - back;
        if (back >= len) {
            memcpy(out + op, ref, len);
        } else {
            for (size_t k = 0; k < len; k++) out[op + k] = ref[k];
        }
        op += len;
    }
    if (op != out_len) {
        *bad_at = in_len;
        return -1;
    }
    return 0;
}
