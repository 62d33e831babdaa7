/* The chain of a ULog data section at C speed: where each record starts.
 *
 * A ULog record is a uint16 size, a uint8 type and `size` bytes; the next record starts right
 * after it, so finding the records is a walk that cannot be vectorised. This walks it and hands
 * back each record's start, size, type and (for data records) msg_id -- read here, where the
 * header is in the cache anyway -- and leaves every decision about the records to
 * Python (codegen/inputs/ulog_index.py): the walk stops, and says where, at the first record
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
    uint8_t pad[3]; /* never written: nobody reads it */
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
    struct head *heads = (struct head *)out.buf;
    Py_ssize_t cap = out.len / (Py_ssize_t)sizeof(struct head), n = 0, p = start, limit = stop - 4;
    Py_BEGIN_ALLOW_THREADS
    while (p < limit && n < cap) {
        unsigned size = (unsigned)d[p] | ((unsigned)d[p + 1] << 8);
        unsigned type = d[p + 2];
        Py_ssize_t next = p + 3 + (Py_ssize_t)size;
        if (next > stop || type == 0 || (!k[type] && (size == 0 || size > MAX_UNKNOWN_SIZE))) {
            break; /* truncated or corrupt: the generated reader's rules decide */
        }
        struct head *h = &heads[n++];
        h->pos = (int64_t)p;
        h->size = (uint16_t)size;
        h->msg_id = (uint16_t)((unsigned)d[p + 3] | ((unsigned)d[p + 4] << 8));
        h->type = (uint8_t)type;
        p = next;
    }
    Py_END_ALLOW_THREADS
    result = Py_BuildValue("(nn)", n, p);
done:
    PyBuffer_Release(&buf);
    PyBuffer_Release(&known);
    PyBuffer_Release(&out);
    return result;
}

static PyMethodDef methods[] = {
    {"scan", scan, METH_VARARGS, "scan(buffer, start, stop, known, out) -> (heads written to out, stop position)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_ulog_scan", "The chain of a ULog data section at C speed.", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__ulog_scan(void) { return PyModule_Create(&module); }
