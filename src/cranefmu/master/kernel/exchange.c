/* The exchange of a macro step in compiled code: FMUs step, the inputs' end values, then every value
 * moves (gather, scale, record, extrapolate with Lagrange weights, scatter, fmi2SetReal), through the
 * FMUs' own FMI function pointers.  The arithmetic is the Python path's (cranefmu/master/coupled.py),
 * operation for operation, so that both give the same bits; build with floating-point contraction off.
 *
 * The extrapolation products reproduce numpy's `w @ stack` for a (k, n) stack as OpenBLAS's gemv
 * computes it on x86-64 (measured; checked against numpy at load by cranefmu.master.kernel): the
 * elements of the leading multiple of 4 fuse the first two products, the rest accumulate in order.
 */
#define _POSIX_C_SOURCE 199309L   /* clock_gettime */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <time.h>

typedef int (*do_step_f)(void *, double, double, int);
typedef int (*get_real_f)(void *, const unsigned int *, size_t, double *);
typedef int (*set_real_f)(void *, const unsigned int *, size_t, const double *);
typedef int (*get_int_f)(void *, const unsigned int *, size_t, int *);
typedef int (*set_int_f)(void *, const unsigned int *, size_t, const int *);

typedef struct {
    /* components */
    int n_comps;
    void **inst;                 /* fmi2Component per component */
    void **do_step, **get_real, **set_real;
    unsigned int **read_vrs;     /* per component: the value references of its one fmi2GetReal */
    int32_t *read_n, *read_at;   /* their count, and where they go in read_buf */
    int32_t *fresh;              /* per component: read_buf holds what the FMU would return now */
    double *fmu_time;            /* seconds inside doStep, per component */
    int64_t *fmu_calls;
    double *read_buf;
    /* the coupling vector */
    int32_t n;
    double *past;                /* 3 x n ring */
    int32_t *ring;               /* [count, row0, row1, row2] oldest first */
    double *times;               /* [t0, t1, t2] oldest first */
    double *fed, *fed_rate, *fed_curv, *input_end, *scale;
    uint8_t *held;
    /* phases */
    int32_t n_phases;
    int32_t *ph_start, *ph_n, *ph_plain;
    int32_t *ph_src_off, *ph_src_n, *src;                 /* sources per phase */
    int64_t *gather;             /* per coupling position: index into read_buf */
    double *factor, *offset;     /* per coupling position */
    int64_t *set_values;         /* per coupling position: index into set_buf */
    int32_t *ph_rate_off, *ph_rate_n;
    int64_t *rate_sel, *set_d1, *set_d2;                  /* rate_sel relative to the phase */
    double *set_buf;
    int32_t *ph_write_off, *ph_write_n;
    int32_t *w_comp, *w_count, *w_start, *w_stales;
    unsigned int **w_vrs;
    double *scratch;             /* 5 x n: the phase's stack (up to 3 x n), d1, d2 */
    /* the row */
    int32_t n_real;
    int64_t *row_gather;
    int32_t n_flag_reads;        /* discrete outputs: one fmi2GetInteger/Boolean each */
    int32_t *f_comp, *f_n, *f_bool;
    void **f_get;                /* fmi2GetInteger or fmi2GetBoolean of that component */
    unsigned int **f_vrs;
    int32_t *f_buf;              /* room for the largest read */
    int32_t n_flags;
    int32_t n_extra_read, n_extra_end;   /* more values per row: read_buf[extra_read[i]], input_end[extra_end[i]] */
    int64_t *extra_read, *extra_end;
    /* connection groups (Gauss-Seidel feeds them one by one) */
    int32_t n_groups;
    int32_t *g_start, *g_n, *g_src, *g_dst, *g_set_at, *g_rates, *g_keeps_fresh;
    int64_t *g_gather;           /* per coupling position: the source's value in read_buf */
    unsigned int **g_vrs;
    /* Gauss-Seidel: per component in stepping order, the groups fed from those stepped before it and
     * (where its outputs feed through) every group into it, held at its end value after its step */
    int32_t n_stages;
    int32_t *s_comp, *s_fed_off, *s_fed_n, *s_held_off, *s_held_n, *s_groups;
    int32_t ends_wanted;
    /* error report */
    int32_t err_comp, err_status, err_what;   /* what: 1 doStep, 2 getReal, 3 setReal, 4 get discrete */
    /* commanded inputs (commands.CommandFeed): per component that has some, one fmi2SetReal of their
     * values (and rates) at a time; the values of all of them at that time side by side (cmd_width) */
    int32_t n_cmd, cmd_width;
    int32_t *cmd_comp, *cmd_count, *cmd_off;
    unsigned int **cmd_vrs;
    int32_t *cmd_of;             /* per component: its write, or -1 */
    double *cmd_values;          /* the values at the step's end; a stretch: one row of cmd_width per step */
    /* FMI input derivatives (fmi2SetRealInputDerivatives) of the groups whose destination takes them */
    void **set_deriv;            /* per component: its fmi2SetRealInputDerivatives (NULL where none is called) */
    int32_t *g_deriv;            /* per group: fed its slopes with fmi2SetRealInputDerivatives */
    int32_t *w_deriv_off, *w_deriv_n, *w_groups;   /* per write of a phase: those of its groups */
    int32_t *ones, *twos;        /* n orders 1 and 2 */
    int32_t *g_keeps_outputs;    /* per group: no output of its destination depends on its inputs */
    /* Integer/Boolean/Enumeration connections (discrete_links.DiscreteLinks): per transfer (a source, a
     * destination, one type) one fmi2GetInteger/Boolean and one fmi2SetInteger/Boolean */
    int32_t n_transfers;
    int32_t *t_src, *t_dst, *t_bool, *t_n;
    unsigned int **t_src_vrs, **t_dst_vrs;
    int **t_values;
    void **d_get, **d_set;       /* per transfer: the source's getter, the destination's setter */
} cf_plan;

typedef int (*set_deriv_f)(void *, const unsigned int *, size_t, const int *, const double *);

static double now_seconds(void)
{
    struct timespec ts;
#ifdef _WIN32
    timespec_get(&ts, TIME_UTC);
#else
    clock_gettime(CLOCK_MONOTONIC, &ts);
#endif
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* sum_i w[i] * a[i][j] as OpenBLAS's gemv gives it for a stack of k rows of n (module doc) */
static double dot_gemv(const double *w, const double *a, int k, int n, int j)
{
    int vec = j < n - n % 4;
    if (k == 2) {
        if (vec)
            return fma(w[0], a[j], w[1] * a[n + j]);
        return fma(w[1], a[n + j], w[0] * a[j]);
    }
    if (vec)
        return fma(w[0], a[j], w[1] * a[n + j]) + w[2] * a[2 * n + j];
    return fma(w[2], a[2 * n + j], fma(w[1], a[n + j], w[0] * a[j]));
}

/* the first and second derivative weights of the polynomial through (ts[i], u_i) at t, as
 * coupling.lagrange_weights computes them */
static void weights(const double *ts, int k, double t, double *w1, double *w2)
{
    if (k == 2) {
        w1[0] = 1.0 / (ts[0] - ts[1]);
        w1[1] = 1.0 / (ts[1] - ts[0]);
        w2[0] = w2[1] = 0.0;
        return;
    }
    for (int i = 0; i < 3; i++) {
        double o[2];
        int m = 0;
        for (int j = 0; j < 3; j++)
            if (j != i)
                o[m++] = ts[j];
        double den = 1.0;
        den *= ts[i] - o[0];
        den *= ts[i] - o[1];
        w1[i] = ((t - o[0]) + (t - o[1])) / den;
        w2[i] = 2.0 / den;
    }
}

static int read_comp(cf_plan *p, int c)
{
    if (p->fresh[c])
        return 0;
    int s = ((get_real_f)p->get_real[c])(p->inst[c], p->read_vrs[c], (size_t)p->read_n[c],
                                         p->read_buf + p->read_at[c]);
    if (s > 1) {
        p->err_comp = c; p->err_status = s; p->err_what = 2;
        return -1;
    }
    p->fresh[c] = 1;
    return 0;
}

/* component c's commanded inputs set to `values` (commands._write): a row of cmd_width, or NULL (none) */
static int set_commands(cf_plan *p, int c, const double *values, int what)
{
    int w = values ? p->cmd_of[c] : -1;
    if (w < 0)
        return 0;
    int s = ((set_real_f)p->set_real[c])(p->inst[c], p->cmd_vrs[w], (size_t)p->cmd_count[w], values + p->cmd_off[w]);
    if (s > 1) {
        p->err_comp = c; p->err_status = s; p->err_what = what;
        return -1;
    }
    p->fresh[c] = 0;
    return 0;
}

/* group g's slopes d1, d2 (n values each) through fmi2SetRealInputDerivatives (coupled.input_derivatives) */
static int set_derivatives(cf_plan *p, int g, const double *d1, const double *d2)
{
    int c = p->g_dst[g];
    size_t n = (size_t)p->g_n[g];
    set_deriv_f f = (set_deriv_f)p->set_deriv[c];
    int s = f(p->inst[c], p->g_vrs[g], n, p->ones, d1);
    if (s <= 1)
        s = f(p->inst[c], p->g_vrs[g], n, p->twos, d2);
    if (s > 1) {
        p->err_comp = c; p->err_status = s; p->err_what = 3;
        return -1;
    }
    return 0;
}

/* every discrete destination input gets its source's current value, all read, then all set
 * (discrete_links.DiscreteLinks.move) */
static int move_discrete(cf_plan *p)
{
    for (int q = 0; q < p->n_transfers; q++) {
        int c = p->t_src[q], n = p->t_n[q];
        int s = ((get_int_f)p->d_get[q])(p->inst[c], p->t_src_vrs[q], (size_t)n, p->t_values[q]);
        if (s > 1) {
            p->err_comp = c; p->err_status = s; p->err_what = 6;
            return -1;
        }
        if (p->t_bool[q])   /* fmi2True is 1, whatever non-zero value the source returns */
            for (int k = 0; k < n; k++)
                p->t_values[q][k] = p->t_values[q][k] ? 1 : 0;
    }
    for (int q = 0; q < p->n_transfers; q++) {
        int c = p->t_dst[q];
        int s = ((set_int_f)p->d_set[q])(p->inst[c], p->t_dst_vrs[q], (size_t)p->t_n[q], p->t_values[q]);
        if (s > 1) {
            p->err_comp = c; p->err_status = s; p->err_what = 7;
            return -1;
        }
        p->fresh[c] = 0;   /* an output may depend on them */
    }
    return 0;
}

/* the ring's row for the values at t (coupled.Coupling._new_point) */
static double *new_point(cf_plan *p, double t)
{
    int32_t *r = p->ring;
    int count = r[0];
    if (count > 0 && p->times[count - 1] == t)
        return p->past + (size_t)r[count] * p->n;
    int row;
    if (count < 3) {
        row = 0;
        for (;;) {
            int used = 0;
            for (int i = 0; i < count; i++)
                used |= r[1 + i] == row;
            if (!used)
                break;
            row++;
        }
        r[1 + count] = row;
        p->times[count] = t;
        r[0] = count + 1;
    } else {
        row = r[1];
        r[1] = r[2]; r[2] = r[3]; r[3] = row;
        p->times[0] = p->times[1]; p->times[1] = p->times[2]; p->times[2] = t;
    }
    return p->past + (size_t)row * p->n;
}

/* the commanded inputs get `cmd` (NULL: none), then the discrete values move (coupled.Coupling.commit_as_read
 * and exchange do both first) */
static int set_commands_and_discrete(cf_plan *p, const double *cmd)
{
    if (cmd)
        for (int w = 0; w < p->n_cmd; w++)
            if (set_commands(p, p->cmd_comp[w], cmd, 3))
                return -1;
    if (p->n_transfers && move_discrete(p))
        return -1;
    return 0;
}

/* the values a..a+n-1 of the last k of the `count` recorded points, oldest first, into stack[k][n] */
static void stack_past(const cf_plan *p, int count, int k, int a, int n, double *stack)
{
    for (int i = 0; i < k; i++) {
        const double *row = p->past + (size_t)p->ring[1 + count - k + i] * p->n + a;
        for (int j = 0; j < n; j++)
            stack[i * n + j] = row[j];
    }
}

/* the first (d1) and second (d2) derivatives of the polynomial through the k rows of stack[k][n], from
 * the weights w1, w2; d2 is 0 unless `curved` */
static void derivatives(const double *w1, const double *w2, const double *stack, int k, int n, int curved,
                        double *d1, double *d2)
{
    for (int j = 0; j < n; j++) {
        d1[j] = dot_gemv(w1, stack, k, n, j);
        d2[j] = curved ? dot_gemv(w2, stack, k, n, j) : 0.0;
    }
}

/* the weights at t of the polynomial through the last k of the `count` recorded points and t + h */
static void step_weights(const cf_plan *p, int count, int k, double t, double h, double *w1, double *w2)
{
    double ts[3];
    for (int i = 0; i < k; i++)
        ts[i] = p->times[count - k + i];
    ts[k] = t + h;
    weights(ts, k + 1, t, w1, w2);
}

/* each input's value at the end of a step of h (coupled.Coupling.note_ends), where the plan wants them */
static void note_ends(cf_plan *p, double h)
{
    if (!p->ends_wanted)
        return;
    double hh = 0.5 * h;
    for (int j = 0; j < p->n; j++)
        p->input_end[j] = p->held[j] ? p->fed[j] : p->fed[j] + h * (p->fed_rate[j] + hh * p->fed_curv[j]);
}

/* the scale of each value: the largest magnitude recorded (np.maximum: a NaN wins) */
static void update_scale(cf_plan *p, const double *new)
{
    for (int j = 0; j < p->n; j++) {
        double v = fabs(new[j]), s = p->scale[j];
        p->scale[j] = (v != v || s != s) ? (v != v ? v : s) : (v > s ? v : s);
    }
}

/* every value moves at t (coupled.Coupling.exchange), extrapolation order `order`; first the commanded
 * inputs get `cmd`, their values at t (NULL: none) */
static int exchange(cf_plan *p, double t, int order, const double *cmd)
{
    if (set_commands_and_discrete(p, cmd))
        return -1;
    double *new = new_point(p, t);
    int count = p->ring[0];
    int k = order + 1 < count ? order + 1 : count;
    double w1[3], w2[3];
    int extrapolate = order > 0 && count >= 2;
    if (extrapolate)
        weights(p->times + (count - k), k, t, w1, w2);
    for (int f = 0; f < p->n_phases; f++) {
        for (int s = p->ph_src_off[f]; s < p->ph_src_off[f] + p->ph_src_n[f]; s++)
            if (read_comp(p, p->src[s]))
                return -1;
        int a = p->ph_start[f], n = p->ph_n[f];
        for (int j = a; j < a + n; j++) {
            double v = p->read_buf[p->gather[j]];
            if (!p->ph_plain[f])
                v = v * p->factor[j] + p->offset[j];
            new[j] = v;
            p->set_buf[p->set_values[j]] = v;
            p->fed[j] = v;
        }
        double *d1 = p->scratch + 3 * (size_t)p->n, *d2 = p->scratch + 4 * (size_t)p->n;
        if (extrapolate) {
            stack_past(p, count, k, a, n, p->scratch);
            derivatives(w1, w2, p->scratch, k, n, order > 1, d1, d2);
        } else {
            for (int j = 0; j < n; j++)
                d1[j] = d2[j] = 0.0;
        }
        for (int r = p->ph_rate_off[f]; r < p->ph_rate_off[f] + p->ph_rate_n[f]; r++) {
            p->set_buf[p->set_d1[r]] = d1[p->rate_sel[r]];
            p->set_buf[p->set_d2[r]] = d2[p->rate_sel[r]];
        }
        for (int j = 0; j < n; j++) {
            p->fed_rate[a + j] = d1[j];
            p->fed_curv[a + j] = d2[j];
            p->held[a + j] = (uint8_t)!extrapolate;
        }
        for (int w = p->ph_write_off[f]; w < p->ph_write_off[f] + p->ph_write_n[f]; w++) {
            int c = p->w_comp[w];
            int s = ((set_real_f)p->set_real[c])(p->inst[c], p->w_vrs[w], (size_t)p->w_count[w],
                                                 p->set_buf + p->w_start[w]);
            if (s > 1) {
                p->err_comp = c; p->err_status = s; p->err_what = 3;
                return -1;
            }
            for (int e = p->w_deriv_off[w]; e < p->w_deriv_off[w] + p->w_deriv_n[w]; e++) {
                int g = p->w_groups[e], b = p->g_start[g] - a;
                if (set_derivatives(p, g, d1 + b, d2 + b))
                    return -1;
            }
            if (p->w_stales[w])
                p->fresh[c] = 0;
        }
    }
    update_scale(p, new);
    return 0;
}

/* component c steps from t by h (coupled.Coupling.do_step); its commanded inputs then get `cmd`, their
 * values at t + h (commands.CommandFeed.after_step) */
static int do_step(cf_plan *p, int c, double t, double h, const double *cmd)
{
    double t0 = now_seconds();
    p->fresh[c] = 0;
    int s = ((do_step_f)p->do_step[c])(p->inst[c], t, h, 1);
    if (s <= 1 && set_commands(p, c, cmd, 1))
        s = -1;
    p->fmu_time[c] += now_seconds() - t0;
    p->fmu_calls[c] += 1;
    if (s > 1) {
        p->err_comp = c; p->err_status = s; p->err_what = 1;
    }
    return s > 1 || s < 0 ? -1 : 0;
}

static int step_all(cf_plan *p, double t, double h, const double *cmd)
{
    for (int c = 0; c < p->n_comps; c++)
        if (do_step(p, c, t, h, cmd))
            return -1;
    double hh = 0.5 * h;
    for (int j = 0; j < p->n; j++)   /* coupled.Coupling.note_ends */
        p->input_end[j] = p->held[j] ? p->fed[j] : p->fed[j] + h * (p->fed_rate[j] + hh * p->fed_curv[j]);
    return 0;
}

/* the row after a step (loop.Sampler): every Real output, then every discrete output as a float */
static int fill_row(cf_plan *p, double *row)
{
    int at = p->n_real;
    for (int q = 0; q < p->n_flag_reads; q++) {
        int c = p->f_comp[q], m = p->f_n[q];
        int s = ((get_int_f)p->f_get[q])(p->inst[c], p->f_vrs[q], (size_t)m, p->f_buf);
        if (s > 1) {
            p->err_comp = c; p->err_status = s; p->err_what = 4;
            return -1;
        }
        for (int i = 0; i < m; i++)
            row[at + i] = p->f_bool[q] ? (p->f_buf[i] ? 1.0 : 0.0) : (double)p->f_buf[i];
        at += m;
    }
    for (int c = 0; c < p->n_comps; c++)
        if (read_comp(p, c))
            return -1;
    for (int j = 0; j < p->n_real; j++)
        row[j] = p->read_buf[p->row_gather[j]];
    double *extra = row + p->n_real + p->n_flags;
    for (int i = 0; i < p->n_extra_read; i++)
        extra[i] = p->read_buf[p->extra_read[i]];
    for (int i = 0; i < p->n_extra_end; i++)
        extra[p->n_extra_read + i] = p->input_end[p->extra_end[i]];
    return 0;
}

/* coupled.Coupling.feed_group: a group's value, rate and curvature into the set buffer and the FMU */
static int feed_group(cf_plan *p, int g, const double *value, const double *d1, const double *d2, int held)
{
    int a = p->g_start[g], n = p->g_n[g], at = p->g_set_at[g], c = p->g_dst[g];
    int count = n;
    for (int j = 0; j < n; j++)
        p->set_buf[at + j] = value[j];
    if (p->g_rates[g]) {
        for (int j = 0; j < n; j++) {
            p->set_buf[at + n + j] = d1[j];
            p->set_buf[at + 2 * n + j] = d2[j];
        }
        count = 3 * n;
    }
    int s = ((set_real_f)p->set_real[c])(p->inst[c], p->g_vrs[g], (size_t)count, p->set_buf + at);
    if (s > 1) {
        p->err_comp = c; p->err_status = s; p->err_what = 3;
        return -1;
    }
    if (p->g_deriv[g] && set_derivatives(p, g, d1, d2))
        return -1;
    if (!p->g_keeps_fresh[g])
        p->fresh[c] = 0;
    for (int j = 0; j < n; j++) {
        p->fed[a + j] = value[j];
        p->fed_rate[a + j] = d1[j];
        p->fed_curv[a + j] = d2[j];
        p->held[a + j] = (uint8_t)held;
    }
    return 0;
}

/* One Gauss-Seidel macro step from t (algorithms.GaussSeidel.step, extrapolation `order`): each
 * component in turn gets the inputs whose source stepped before it along the polynomial through the past
 * values and the source's new value, steps, and (where its outputs feed through) holds its inputs at
 * their end values; then the inputs' end values, then every value moves at t + h. */
int cf_gauss_seidel_step(cf_plan *p, double t, double h, int order)
{
    const double *cmd = p->n_cmd ? p->cmd_values : NULL;
    double *u = p->scratch, *d1 = p->scratch + p->n, *d2 = p->scratch + 2 * (size_t)p->n;
    double *stack = p->scratch + 3 * (size_t)p->n;   /* up to 2 x n more: the scratch holds 5 x n */
    int count = p->ring[0];
    int k = order < count ? order : count;            /* past points used (coupled.Coupling._last) */
    double w1[3], w2[3];
    if (order > 0)
        step_weights(p, count, k, t, h, w1, w2);
    const double *newest = count ? p->past + (size_t)p->ring[count] * p->n : NULL;
    for (int q = 0; q < p->n_stages; q++) {
        for (int e = p->s_fed_off[q]; e < p->s_fed_off[q] + p->s_fed_n[q]; e++) {
            int g = p->s_groups[e], a = p->g_start[g], n = p->g_n[g];
            if (read_comp(p, p->g_src[g]))
                return -1;
            for (int j = 0; j < n; j++)   /* coupled.Coupling.pull: read x factor + offset */
                u[j] = p->read_buf[p->g_gather[a + j]] * p->factor[a + j] + p->offset[a + j];
            if (order == 0) {
                for (int j = 0; j < n; j++)
                    d1[j] = d2[j] = 0.0;
                if (feed_group(p, g, u, d1, d2, 0))
                    return -1;
                continue;
            }
            stack_past(p, count, k, a, n, stack);
            for (int j = 0; j < n; j++)
                stack[k * n + j] = u[j];
            derivatives(w1, w2, stack, k + 1, n, 1, d1, d2);
            if (feed_group(p, g, newest + a, d1, d2, 0))
                return -1;
        }
        if (do_step(p, p->s_comp[q], t, h, cmd))
            return -1;
        double hh = 0.5 * h;
        for (int e = p->s_held_off[q]; e < p->s_held_off[q] + p->s_held_n[q]; e++) {
            int g = p->s_groups[e], a = p->g_start[g], n = p->g_n[g];
            for (int j = 0; j < n; j++) {   /* coupled.Coupling.hold_ends */
                u[j] = p->fed[a + j] + h * (p->fed_rate[a + j] + hh * p->fed_curv[a + j]);
                d1[j] = d2[j] = 0.0;
            }
            if (feed_group(p, g, u, d1, d2, 0))
                return -1;
        }
    }
    note_ends(p, h);
    return exchange(p, t + h, order, cmd);
}

/* G(u) of a strongly coupled step (algorithms.Iterative._evaluate, implicit_group.ImplicitGroup._evaluate):
 * the groups `groups` (a coupled.Part: u and gu in their order) are fed the polynomial through their last
 * `degree` values and u at t + h (coupled.Coupling.feed; `batched`: the part's rates in one product, as
 * Part(batched=True) has them), the components `members` step from t by h (their commanded inputs then
 * at t + h; `ends`: the inputs' end values noted where wanted), and what the groups' sources give is read
 * into gu and passed on (coupled.Coupling.image; `through_only`: only where an output of the destination
 * depends on it, as a hold).  Needs count >= 1 past point and degree <= 2 (the caller checks).
 * Returns 0, or -1 (err_*). */
int cf_evaluate(cf_plan *p, double t, double h, int degree, int batched, int through_only, int ends,
                int n_g, const int32_t *groups, int n_m, const int32_t *members, const double *u, double *gu)
{
    const double *cmd = p->n_cmd ? p->cmd_values : NULL;
    size_t nn = (size_t)p->n;
    double *stack = p->scratch, *d1 = p->scratch + 3 * nn, *d2 = p->scratch + 4 * nn, *zero = p->scratch + 5 * nn;
    int n = 0;
    for (int e = 0; e < n_g; e++)
        n += p->g_n[groups[e]];
    for (int j = 0; j < n; j++)
        zero[j] = 0.0;
    int count = p->ring[0];
    if (degree == 0) {   /* held over the step */
        for (int e = 0, off = 0; e < n_g; off += p->g_n[groups[e]], e++)
            if (feed_group(p, groups[e], u + off, zero, zero, batched))
                return -1;
    } else {
        int k = degree < count ? degree : count;   /* coupled.Coupling._last(degree) */
        double w1[3], w2[3];
        step_weights(p, count, k, t, h, w1, w2);
        if (batched && count >= degree + 1) {   /* one product over the whole part */
            for (int i = 0; i < k; i++) {
                const double *row = p->past + (size_t)p->ring[1 + count - k + i] * nn;
                for (int e = 0, off = 0; e < n_g; off += p->g_n[groups[e]], e++)
                    for (int j = 0; j < p->g_n[groups[e]]; j++)
                        stack[i * n + off + j] = row[p->g_start[groups[e]] + j];
            }
            for (int j = 0; j < n; j++)
                stack[k * n + j] = u[j];
            derivatives(w1, w2, stack, k + 1, n, 1, d1, d2);
            const double *now = stack + (size_t)(k - 1) * n;
            for (int e = 0, off = 0; e < n_g; off += p->g_n[groups[e]], e++)
                if (feed_group(p, groups[e], now + off, d1 + off, d2 + off, 0))
                    return -1;
        } else {   /* group by group */
            const double *newest = p->past + (size_t)p->ring[count] * nn;
            for (int e = 0, off = 0; e < n_g; off += p->g_n[groups[e]], e++) {
                int g = groups[e], a = p->g_start[g], m = p->g_n[g];
                stack_past(p, count, k, a, m, stack);
                for (int j = 0; j < m; j++)
                    stack[k * m + j] = u[off + j];
                derivatives(w1, w2, stack, k + 1, m, 1, d1, d2);
                if (feed_group(p, g, newest + a, d1, d2, 0))
                    return -1;
            }
        }
    }
    for (int i = 0; i < n_m; i++)
        if (do_step(p, members[i], t, h, cmd))
            return -1;
    if (ends)
        note_ends(p, h);
    for (int e = 0, off = 0; e < n_g; off += p->g_n[groups[e]], e++) {
        int g = groups[e], a = p->g_start[g], m = p->g_n[g];
        if (read_comp(p, p->g_src[g]))
            return -1;
        for (int j = 0; j < m; j++)   /* coupled.Coupling.pull */
            gu[off + j] = p->read_buf[p->g_gather[a + j]] * p->factor[a + j] + p->offset[a + j];
        if (!through_only || !p->g_keeps_outputs[g])
            if (feed_group(p, g, gu + off, zero, zero, through_only))
                return -1;
    }
    return 0;
}

/* One step of libcosim's fixed-step Jacobi from t (algorithms.PlainJacobi.step): every FMU steps, then
 * (coupled.Coupling.commit_as_read) the commanded inputs are set, every output is read once and held by
 * its input over the next step, the values recorded at t + h; every read then counts as fresh (the row
 * shows what was read right after the step).  Returns 0, or -1 (err_*). */
int cf_plain_step(cf_plan *p, double t, double h)
{
    const double *cmd = p->n_cmd ? p->cmd_values : NULL;
    double *zero = p->scratch + 5 * (size_t)p->n;
    if (step_all(p, t, h, cmd) || set_commands_and_discrete(p, cmd))
        return -1;
    for (int c = 0; c < p->n_comps; c++)
        if (read_comp(p, c))
            return -1;
    double *new = new_point(p, t + h);
    for (int j = 0; j < p->n; j++)
        zero[j] = 0.0;
    for (int g = 0; g < p->n_groups; g++) {
        int a = p->g_start[g], n = p->g_n[g];
        for (int j = 0; j < n; j++)   /* coupled.Coupling.pull */
            new[a + j] = p->read_buf[p->g_gather[a + j]] * p->factor[a + j] + p->offset[a + j];
        if (feed_group(p, g, new + a, zero, zero, 1))
            return -1;
    }
    for (int c = 0; c < p->n_comps; c++)
        p->fresh[c] = 1;
    update_scale(p, new);
    return 0;
}

/* Every value moves at t (coupled.Coupling.commit after a step an algorithm took in Python: iterative,
 * an implicit group, the start-up), the commanded inputs first.  Returns 0, or -1 (err_*). */
int cf_exchange(cf_plan *p, double t, int order)
{
    return exchange(p, t, order, p->n_cmd ? p->cmd_values : NULL);
}

/* One Jacobi macro step from t: every FMU steps, the inputs' end values are noted, every value moves
 * at t + h.  Returns 0, or -1 with the failure in err_*. */
int cf_jacobi_step(cf_plan *p, double t, double h, int order)
{
    const double *cmd = p->n_cmd ? p->cmd_values : NULL;
    if (step_all(p, t, h, cmd))
        return -1;
    return exchange(p, t + h, order, cmd);
}

/* `steps` Jacobi macro steps on the grid ts[0..steps] (step i from ts[i] to ts[i + 1], h = their
 * difference, as the loop's FixedSteps proposes it), each row (time, the Real outputs, the discrete
 * outputs, the extra values) into rows[i * (1 + n_real + n_flags + n_extra_read + n_extra_end)].  Returns the steps done, or -1 - steps done on a
 * failure (err_*). */
int cf_jacobi_steps(cf_plan *p, const double *ts, int order, int steps, double *rows)
{
    for (int i = 0; i < steps; i++) {
        double t = ts[i], h = ts[i + 1] - ts[i];
        const double *cmd = p->n_cmd ? p->cmd_values + (size_t)i * p->cmd_width : NULL;
        if (step_all(p, t, h, cmd) || exchange(p, ts[i + 1], order, cmd))
            return -1 - i;
        double *row = rows + (size_t)i * (1 + p->n_real + p->n_flags + p->n_extra_read + p->n_extra_end);
        row[0] = ts[i + 1];
        if (fill_row(p, row + 1))
            return -1 - i;
    }
    return steps;
}

/* the extrapolation product alone, for the check against numpy at load: out[j] = sum_i w[i] a[i][j] */
void cf_dot_gemv(const double *w, const double *a, int k, int n, double *out)
{
    for (int j = 0; j < n; j++)
        out[j] = dot_gemv(w, a, k, n, j);
}

void cf_weights(const double *ts, int k, double t, double *w1, double *w2)
{
    weights(ts, k, t, w1, w2);
}
