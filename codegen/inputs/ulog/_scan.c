/* The chain of a ULog data section at C speed: where each record starts.
 *
 * A ULog record is a uint16 size, a uint8 type and `size` bytes; the next record starts right
 * after it, so finding the records is a walk that cannot be vectorised. This walks it and hands
 * back each record's start, size, type and (for data records) msg_id -- read here, where the
 * header is in the cache anyway -- and leaves every decision about the records to
 * Python (codegen/inputs/ulog/index.py): the walk stops, and says where, at the first record
 * the generated reader treats specially (one that runs past `stop`, or a corrupt header it
 * resynchronises after), so Python's rules stay the only ones.
 *
 * scan(buffer, start, stop, known, out) -> (records written to out, where the walk stopped)
 *   buffer: any bytes-like object (a memory map); records are read in [start, stop)
 *   known:  256 bytes, known[t] != 0 for the record types the reader knows
 *   out:    a writable buffer of struct head; the walk also stops when it is full (the caller
 *           reuses one small buffer, which stays in the CPU's cache, and calls again)
 * The walk visits records starting before stop - 4 (the generated walker reads a 'D' record's
 * size, type and msg_id, 5 bytes, in one step and leaves the last 4 bytes to its slower path).
 *
 * gather(buffer, offsets, record_size, fields) -> None
 *   offsets: a C-contiguous buffer of native int64 (a numpy int64 array): payload offsets of
 *            records of one format; every record must lie in buffer
 *   fields:  a sequence of (offset in the record, size, out): out, a writable buffer of at least
 *            len(offsets) * size bytes, receives each record's field bytes back to back
 * One pass over the records copies every wanted field out of each while its cache lines are
 * loaded (ulog_columns.py reads the columns through numpy dtypes; this only moves bytes).
 *
 * Both are callable from Python with any arguments, so every bound is checked before a byte is
 * touched, in unsigned 64-bit arithmetic written as differences of values already known to be in
 * range (a - b with b <= a), never as sums that could wrap; a refusal is a ValueError or
 * TypeError. Buffers are read and written with memcpy, so no alignment is assumed of them.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <string.h>

#define MAX_UNKNOWN_SIZE 10000 /* the generated reader's bound for a record of an unknown type */

/* One record, 16 bytes in native byte order (ulog_index.py's numpy dtype mirrors it). */
struct head {
    int64_t pos;
    uint16_t size;
    uint16_t msg_id; /* the two bytes after the type: a data record's msg_id */
    uint8_t type;
    uint8_t pad[3]; /* zero: nobody reads it */
};

static PyObject *scan(PyObject *self, PyObject *args) {
    Py_buffer buf, known, out;
    Py_ssize_t start, stop;
    (void)self;
    if (!PyArg_ParseTuple(args, "y*nny*w*", &buf, &start, &stop, &known, &out)) {
        return NULL;
    }
    PyObject *result = NULL;
    if (known.len != 256 || start < 0 || stop < start || stop > buf.len) {
        PyErr_SetString(PyExc_ValueError, "scan: expected 0 <= start <= stop <= len(buffer) and 256 known flags");
        goto done;
    }
    const unsigned char *d = (const unsigned char *)buf.buf;
    const unsigned char *k = (const unsigned char *)known.buf;
    char *heads = (char *)out.buf;
    /* With 0 <= start <= stop <= len(buffer), p < stop - 4 keeps the 5 header bytes in bounds, and
     * the record's end is compared as a difference (size + 3 against stop - p), not a sum. */
    Py_ssize_t cap = out.len / (Py_ssize_t)sizeof(struct head), n = 0, p = start, limit = stop - 4;
    Py_BEGIN_ALLOW_THREADS
    while (p < limit && n < cap) {
        unsigned size = (unsigned)d[p] | ((unsigned)d[p + 1] << 8);
        unsigned type = d[p + 2];
        if ((size_t)size + 3 > (size_t)(stop - p) || type == 0 ||
            (!k[type] && (size == 0 || size > MAX_UNKNOWN_SIZE))) {
            break; /* truncated or corrupt: the generated reader's rules decide */
        }
        struct head h = {(int64_t)p, (uint16_t)size, (uint16_t)((unsigned)d[p + 3] | ((unsigned)d[p + 4] << 8)),
                         (uint8_t)type, {0, 0, 0}};
        memcpy(heads + (size_t)n * sizeof h, &h, sizeof h);
        n++;
        p += 3 + (Py_ssize_t)size;
    }
    Py_END_ALLOW_THREADS
    result = Py_BuildValue("(nn)", n, p);
done:
    PyBuffer_Release(&buf);
    PyBuffer_Release(&known);
    PyBuffer_Release(&out);
    return result;
}

#define MAX_FIELDS 512

struct field {
    Py_ssize_t offset, size;
    char *out;
};

/* A field's bytes; the common sizes as fixed-size copies the compiler turns into single moves. */
static inline void copy_field(char *dst, const unsigned char *src, Py_ssize_t size) {
    switch (size) {
    case 1: *dst = (char)*src; break;
    case 2: memcpy(dst, src, 2); break;
    case 4: memcpy(dst, src, 4); break;
    case 8: memcpy(dst, src, 8); break;
    default: memcpy(dst, src, (size_t)size);
    }
}

/* Whether a buffer holds native int64 values: 8-byte items of format 'q' or 'l' (numpy's int64 on
 * LP64 systems), in the machine's byte order. */
static int is_native_int64(const Py_buffer *b) {
    const char *f = b->format ? b->format : "B";
    if (*f == '@' || *f == '=' || *f == (PY_LITTLE_ENDIAN ? '<' : '>')) {
        f++;
    }
    return b->itemsize == 8 && (strcmp(f, "q") == 0 || strcmp(f, "l") == 0);
}

static PyObject *gather(PyObject *self, PyObject *args) {
    Py_buffer buf, offs;
    Py_ssize_t record_size;
    PyObject *offsets, *spec;
    (void)self;
    if (!PyArg_ParseTuple(args, "y*OnO", &buf, &offsets, &record_size, &spec)) {
        return NULL;
    }
    if (PyObject_GetBuffer(offsets, &offs, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        PyBuffer_Release(&buf);
        return NULL;
    }
    /* A tuple of the fields, ours alone: parsing an item can run Python code (an __index__), which
     * must not be able to change or free the items under the loop. */
    PyObject *result = NULL, *items = PySequence_Tuple(spec);
    Py_buffer outs[MAX_FIELDS];
    struct field fields[MAX_FIELDS];
    Py_ssize_t nf = 0, count = offs.len / 8;
    if (items == NULL) {
        goto done;
    }
    if (!is_native_int64(&offs) || offs.len % 8 != 0) {
        PyErr_SetString(PyExc_TypeError, "gather: expected the offsets as native int64 values (a numpy int64 array)");
        goto done;
    }
    if (PyTuple_GET_SIZE(items) > MAX_FIELDS || record_size < 0) {
        PyErr_SetString(PyExc_ValueError, "gather: too many fields, or a negative record size");
        goto done;
    }
    for (Py_ssize_t j = 0; j < PyTuple_GET_SIZE(items); j++) {
        PyObject *item = PyTuple_GET_ITEM(items, j);
        struct field *f = &fields[nf];
        if (!PyTuple_Check(item)) {
            PyErr_SetString(PyExc_TypeError, "gather: expected each field as a tuple (offset, size, out)");
            goto done;
        }
        if (!PyArg_ParseTuple(item, "nnw*", &f->offset, &f->size, &outs[nf])) {
            goto done;
        }
        nf++;
        /* offset <= record_size, then size <= record_size - offset: no sum to overflow */
        if (f->offset < 0 || f->size < 0 || f->offset > record_size || f->size > record_size - f->offset ||
            outs[nf - 1].len / (f->size ? f->size : 1) < count) {
            PyErr_SetString(PyExc_ValueError, "gather: a field outside the record, or an output too small");
            goto done;
        }
        f->out = (char *)outs[nf - 1].buf;
    }
    const unsigned char *d = (const unsigned char *)buf.buf;
    const char *at = (const char *)offs.buf;
    const uint64_t length = (uint64_t)buf.len, width = (uint64_t)record_size;
    int bad = 0;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < count; i++) {
        int64_t o;
        memcpy(&o, at + (size_t)i * 8, 8);
        /* the record [o, o + width) inside [0, length): o <= length, then width <= length - o */
        if (o < 0 || (uint64_t)o > length || width > length - (uint64_t)o) {
            bad = 1;
            break;
        }
        for (Py_ssize_t j = 0; j < nf; j++) {
            copy_field(fields[j].out + i * fields[j].size, d + o + fields[j].offset, fields[j].size);
        }
    }
    Py_END_ALLOW_THREADS
    if (bad) {
        PyErr_SetString(PyExc_ValueError, "gather: a record outside the buffer");
        goto done;
    }
    result = Py_NewRef(Py_None);
done:
    for (Py_ssize_t j = 0; j < nf; j++) {
        PyBuffer_Release(&outs[j]);
    }
    Py_XDECREF(items);
    PyBuffer_Release(&buf);
    PyBuffer_Release(&offs);
    return result;
}

static PyMethodDef methods[] = {
    {"scan", scan, METH_VARARGS, "scan(buffer, start, stop, known, out) -> (heads written to out, stop position)"},
    {"gather", gather, METH_VARARGS, "gather(buffer, offsets, record_size, fields) -> None: fields out of records"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_scan", "The chain of a ULog data section at C speed.", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__scan(void) { return PyModule_Create(&module); }
