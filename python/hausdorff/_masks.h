/* _masks.h -- the functions of _masks.c, added to the module by _hausdorff.c. */
#ifndef HD_PY_MASKS_H
#define HD_PY_MASKS_H
#include <Python.h>
extern PyMethodDef hd_py_mask_methods[];
#endif
