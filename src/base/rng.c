/*
 * rng.c -- seeded randomness: xoshiro256** seeded through splitmix64.
 *
 * The library never reads the clock or /dev/urandom for randomness: every
 * random choice (EARLYBREAK's shuffles, OHD's sample, mesh sampling) comes
 * from a generator seeded by the caller's explicit seed, so a run can be
 * repeated exactly.  Bounded integers use Lemire's multiply-and-reject
 * method, so there is no modulo bias.
 */
#include "base/base.h"

static uint64_t splitmix64(uint64_t *x) {
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

void hd__rng_seed(hd__rng_t *r, uint64_t seed) {
    uint64_t x = seed;
    for (int k = 0; k < 4; k++) r->s[k] = splitmix64(&x);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

uint64_t hd__rng_next(hd__rng_t *r) {
    uint64_t *s = r->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

uint64_t hd__rng_below(hd__rng_t *r, uint64_t n) {
    unsigned __int128 m = (unsigned __int128)hd__rng_next(r) * n;
    uint64_t low = (uint64_t)m;
    if (low < n) {
        uint64_t threshold = (0 - n) % n;
        while (low < threshold) {
            m = (unsigned __int128)hd__rng_next(r) * n;
            low = (uint64_t)m;
        }
    }
    return (uint64_t)(m >> 64);
}

double hd__rng_unit(hd__rng_t *r) {
    return (double)(hd__rng_next(r) >> 11) * 0x1.0p-53;
}

void hd__rng_permute(hd__rng_t *r, size_t *perm, size_t n) {
    for (size_t k = 0; k < n; k++) perm[k] = k;
    for (size_t k = n; k > 1; k--) {
        size_t j = (size_t)hd__rng_below(r, k);
        size_t t = perm[k - 1];
        perm[k - 1] = perm[j];
        perm[j] = t;
    }
}
