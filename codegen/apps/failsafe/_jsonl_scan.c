/* A JSON Lines stream of one line shape read into columns at C speed (jsonl_columns.py decides everything else).
 *
 * A stream a program writes repeats its first line's text with only the values changing. Python reads that first
 * line with json, checks its shape and cuts it into literals (the text between values: keys, punctuation, spaces)
 * and slots (where a value goes). This walks the whole buffer once, line after line: every literal must be there
 * byte for byte, every slot must hold one JSON number (RFC 8259's grammar), `null` or a boolean as the slot allows,
 * and every line must end where the template does (a newline, or the buffer's end for the last line). Anything else
 * -- a blank or comment line, another shape -- stops the walk and returns -1, and
 * the caller reads the stream sample by sample as before, with its errors: this never decides an error.
 *
 * A number is read as json.loads and then float() read it: correctly rounded. A token of at most 19 digits without
 * an exponent whose digits make an integer below 2**53 and whose point is at most 22 places from the end is that
 * integer divided by a power of ten, both exact doubles, so the one IEEE division is the correctly rounded value.
 * Any other token goes through PyOS_string_to_double (Python's own float() parser); an integer token (no point, no
 * exponent) is an int to json, so "-0" is +0.0 and a magnitude beyond a double is inf (the caller refuses inf).
 *
 * scan(buffer, literals, slots, columns, armed, starts) -> lines read, or -1
 *   buffer:   bytes-like (a memory map of the file)
 *   literals: a tuple of n + 1 bytes objects; slots: a bytes object of n slot codes (below)
 *   columns:  a writable buffer of native float64, column-major: column c's line k at c * capacity + k, where
 *             capacity = len(columns) / 8 / 5
 *   armed:    a writable buffer of at least capacity bytes (1 armed, 0 not)
 *   starts:   a writable buffer of at least capacity + 1 native int64: each line's first byte, then the end of the
 *             last line plus one (so line k is buffer[starts[k]:starts[k + 1] - 1])
 * Slot codes: 0..4 a number of that column (0 t, 1 instance, 2 voltage, 3 current, 4 consumed): t takes no null,
 * instance takes an integer token only, 2..4 take null (NaN); 5 is armed: true or false.
 * Every argument is checked before a byte is touched; a line past capacity stops the walk (-1). The walk keeps the
 * GIL: a slow token calls Python's float parser, and the CLI has no other thread to give it to.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#define COLUMNS 5
#define ARMED 5
#define TOKEN_MAX 64
#define MAX_SLOTS 16

static const double POW10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

#define IS_DIGIT(c) ((unsigned char)((c) - '0') < 10)

/* Whether the n bytes at p are the literal's: eight at a time (memcmp is a call per literal, six a line). */
static inline int same(const char *p, const char *lit, Py_ssize_t n) {
    uint64_t a, b;
    while (n >= 8) {
        memcpy(&a, p, 8);
        memcpy(&b, lit, 8);
        if (a != b) {
            return 0;
        }
        p += 8;
        lit += 8;
        n -= 8;
    }
    while (n > 0) {
        if (*p++ != *lit++) {
            return 0;
        }
        n--;
    }
    return 1;
}

/* One JSON number at p (before end): its value in *out, the byte after it returned; NULL when p holds no number
 * (or null where nulls are refused, or a non-integer where `integer` asks for one). */
static const char *number(const char *p, const char *end, int nullable, int integer, double *out) {
    const char *start = p;
    if (nullable && end - p >= 4 && memcmp(p, "null", 4) == 0) {
        *out = NAN;
        return p + 4;
    }
    int neg = 0;
    if (p < end && *p == '-') {
        neg = 1;
        p++;
    }
    if (p >= end || !IS_DIGIT(*p)) {
        return NULL;
    }
    uint64_t mant = 0;
    int digits = 0;
    if (*p == '0') {
        p++;
    } else {
        while (p < end && IS_DIGIT(*p)) {
            if (digits < 19) {
                mant = mant * 10 + (uint64_t)(*p - '0');
            }
            digits++;
            p++;
        }
    }
    int frac = 0;
    int point = 0;
    if (p < end && *p == '.') {
        point = 1;
        p++;
        if (p >= end || !IS_DIGIT(*p)) {
            return NULL;
        }
        while (p < end && IS_DIGIT(*p)) {
            if (digits < 19) {
                mant = mant * 10 + (uint64_t)(*p - '0');
            }
            if (mant != 0 || digits) {
                digits++; /* leading zeros of the fraction are not significant: they only shift the point */
            }
            frac++;
            p++;
        }
    }
    int exponent = 0;
    if (p < end && (*p == 'e' || *p == 'E')) {
        exponent = 1;
        p++;
        if (p < end && (*p == '+' || *p == '-')) {
            p++;
        }
        if (p >= end || !IS_DIGIT(*p)) {
            return NULL;
        }
        while (p < end && IS_DIGIT(*p)) {
            p++;
        }
    }
    if (integer && (point || exponent)) {
        return NULL;
    }
    if (!exponent && digits <= 19 && mant <= ((uint64_t)1 << 53) && frac <= 22) {
        double v = (double)mant / POW10[frac];
        *out = neg && (point || mant != 0) ? -v : v;
        return p;
    }
    Py_ssize_t size = p - start;
    char small[TOKEN_MAX];
    char *token = size < TOKEN_MAX ? small : PyMem_Malloc((size_t)size + 1);
    if (token == NULL) {
        return NULL;
    }
    memcpy(token, start, (size_t)size);
    token[size] = '\0';
    char *stop = NULL;
    double v = PyOS_string_to_double(token, &stop, NULL); /* inf past a double's range: no exception */
    int bad = (v == -1.0 && PyErr_Occurred()) || stop != token + size;
    if (token != small) {
        PyMem_Free(token);
    }
    if (bad) {
        PyErr_Clear();
        return NULL;
    }
    *out = (!point && !exponent && v == 0.0) ? 0.0 : v; /* the integer -0 is json's int 0 */
    return p;
}

static PyObject *scan(PyObject *self, PyObject *args) {
    Py_buffer buf, slots_buf, cols, armed, starts;
    PyObject *literals;
    (void)self;
    if (!PyArg_ParseTuple(args, "y*O!y*w*w*w*", &buf, &PyTuple_Type, &literals, &slots_buf, &cols, &armed,
                          &starts)) {
        return NULL;
    }
    PyObject *result = NULL;
    Py_ssize_t n = slots_buf.len;
    const char *lit[MAX_SLOTS + 1];
    Py_ssize_t lit_len[MAX_SLOTS + 1];
    const unsigned char *slots = (const unsigned char *)slots_buf.buf;
    if (n < 1 || n > MAX_SLOTS || PyTuple_GET_SIZE(literals) != n + 1) {
        PyErr_SetString(PyExc_ValueError, "scan: expected 1 to 16 slots and one literal more");
        goto done;
    }
    for (Py_ssize_t i = 0; i <= n; i++) {
        PyObject *item = PyTuple_GET_ITEM(literals, i);
        if (!PyBytes_Check(item)) {
            PyErr_SetString(PyExc_TypeError, "scan: expected bytes literals");
            goto done;
        }
        lit[i] = PyBytes_AS_STRING(item);
        lit_len[i] = PyBytes_GET_SIZE(item);
        if (i < n && slots[i] > ARMED) {
            PyErr_SetString(PyExc_ValueError, "scan: expected slot codes 0 to 5");
            goto done;
        }
    }
    Py_ssize_t capacity = cols.len / (Py_ssize_t)sizeof(double) / COLUMNS;
    if (armed.len < capacity || starts.len / (Py_ssize_t)sizeof(int64_t) < capacity + 1) {
        PyErr_SetString(PyExc_ValueError, "scan: expected armed and starts buffers for every line of columns");
        goto done;
    }
    const char *p = (const char *)buf.buf;
    const char *end = p + buf.len;
    const char *base = p;
    double value;
    Py_ssize_t k = 0;
    int ok = 1;
    while (p < end) {
        if (k >= capacity) {
            ok = 0;
            break;
        }
        int64_t at = (int64_t)(p - base);
        memcpy((char *)starts.buf + (size_t)k * sizeof(int64_t), &at, sizeof(int64_t));
        for (Py_ssize_t i = 0; i <= n && ok; i++) {
            if (end - p < lit_len[i] || !same(p, lit[i], lit_len[i])) {
                ok = 0;
                break;
            }
            p += lit_len[i];
            if (i == n) {
                break;
            }
            int slot = slots[i];
            if (slot == ARMED) {
                unsigned char flag;
                if (end - p >= 4 && memcmp(p, "true", 4) == 0) {
                    flag = 1;
                    p += 4;
                } else if (end - p >= 5 && memcmp(p, "false", 5) == 0) {
                    flag = 0;
                    p += 5;
                } else {
                    ok = 0;
                    break;
                }
                ((unsigned char *)armed.buf)[k] = flag;
                continue;
            }
            const char *next;
            if (slot >= 2) {
                next = number(p, end, 1, 0, &value);
            } else {
                next = number(p, end, 0, slot == 1, &value);
            }
            if (next == NULL) {
                ok = 0;
                break;
            }
            p = next;
            memcpy((char *)cols.buf + ((size_t)slot * (size_t)capacity + (size_t)k) * sizeof(double), &value,
                   sizeof(double));
        }
        if (!ok) {
            break;
        }
        if (p < end) {
            if (*p != '\n') {
                ok = 0;
                break;
            }
            p++;
        }
        k++;
    }
    if (ok) {
        int64_t last = (int64_t)(p - base) + (buf.len > 0 && base[buf.len - 1] == '\n' ? 0 : 1);
        memcpy((char *)starts.buf + (size_t)k * sizeof(int64_t), &last, sizeof(int64_t));
    }
    result = PyLong_FromSsize_t(ok ? k : -1);
done:
    PyBuffer_Release(&buf);
    PyBuffer_Release(&slots_buf);
    PyBuffer_Release(&cols);
    PyBuffer_Release(&armed);
    PyBuffer_Release(&starts);
    return result;
}

static PyMethodDef methods[] = {
    {"scan", scan, METH_VARARGS, "scan(buffer, literals, slots, columns, armed, starts) -> lines read, or -1"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_jsonl_scan", NULL, -1, methods};

PyMODINIT_FUNC PyInit__jsonl_scan(void) { return PyModule_Create(&module); }
