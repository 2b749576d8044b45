#include "io.h"
int hd__write_laz(hd__writer_t *w) {
    return hd__err(w->err, HD_EUNSUPPORTED, "%s: LAZ", w->in->name);
}
