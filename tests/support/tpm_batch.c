/* Test harness for the generated tpm_2ppa.c (tests/exchange): every function on n rows of inputs.
 *
 * Row of IN_COLS inputs: prm[0:7] (a, b, l_a, m_a, m_b, m_p, stroke), p[7:9], dp[9:11], ddp[11:13], f_ext[13:15],
 * kp[15:17], kd[17:19], p_ref[19:21], dp_ref[21:23], ddp_ref[23:25], tau_in[25:27] (for the forward dynamics),
 * then the margin of tpm_params: min_cos[27], min_det[28].
 * Row of OUT_COLS outputs (the caller pre-fills them with a sentinel; a refusing function must leave it):
 * d[0:2] rc_ik[2] J[3:7] rc_jac[7] tau[8:10] rc_id[10] ddp[11:13] rc_fd[13] tau_ctc[14:16] rc_ctc[16]
 * rc_stroke[17] (tpm_check_stroke of the input p read as actuator positions); then the parallel arrangement's
 * tpm_par_*: d[18:20] rc[20] J[21:25] rc[25] tau[26:28] rc[28] ddp[29:31] rc[31].
 * Built as a shared library (ctypes) or, with -DTPM_DRIVER, as a program: driver IN_FILE OUT_FILE (raw doubles).
 */
#include "tpm_2ppa.h"

#include <stddef.h>

#define IN_COLS 29
#define OUT_COLS 32

void batch_all(size_t n, const double *in, double *out);

void batch_all(size_t n, const double *in, double *out)
{
    size_t k;
    for (k = 0; k < n; ++k) {
        const double *r = in + k * IN_COLS;
        double *o = out + k * OUT_COLS;
        tpm_params prm;
        prm.a = r[0];
        prm.b = r[1];
        prm.l_a = r[2];
        prm.m_a = r[3];
        prm.m_b = r[4];
        prm.m_p = r[5];
        prm.stroke = r[6];
        prm.min_cos = r[27];
        prm.min_det = r[28];
        o[2] = tpm_inverse_kinematics(&prm, r + 7, o + 0);
        o[7] = tpm_jacobian(&prm, r + 7, o + 3);
        o[10] = tpm_inverse_dynamics(&prm, r + 7, r + 9, r + 11, r + 13, o + 8);
        o[13] = tpm_forward_dynamics(&prm, r + 7, r + 9, r + 25, r + 13, o + 11);
        o[16] = tpm_computed_torque(&prm, r + 15, r + 17, r + 19, r + 21, r + 23, r + 7, r + 9, o + 14);
        o[17] = tpm_check_stroke(&prm, r + 7);
        o[20] = tpm_par_inverse_kinematics(&prm, r + 7, o + 18);
        o[25] = tpm_par_jacobian(&prm, r + 7, o + 21);
        o[28] = tpm_par_inverse_dynamics(&prm, r + 7, r + 9, r + 11, r + 13, o + 26);
        o[31] = tpm_par_forward_dynamics(&prm, r + 7, r + 9, r + 25, r + 13, o + 29);
    }
}

#ifdef TPM_DRIVER
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    FILE *fin, *fout;
    long bytes;
    size_t n, i;
    double *in, *out;
    if (argc != 3 || (fin = fopen(argv[1], "rb")) == NULL) {
        return 2;
    }
    fseek(fin, 0, SEEK_END);
    bytes = ftell(fin);
    fseek(fin, 0, SEEK_SET);
    n = (size_t)bytes / (IN_COLS * sizeof(double));
    in = malloc(n * IN_COLS * sizeof(double) + 1);
    out = malloc(n * OUT_COLS * sizeof(double) + 1);
    if (in == NULL || out == NULL || fread(in, sizeof(double), n * IN_COLS, fin) != n * IN_COLS) {
        return 3;
    }
    fclose(fin);
    for (i = 0; i < n * OUT_COLS; ++i) {
        out[i] = 12345.0;
    }
    batch_all(n, in, out);
    if ((fout = fopen(argv[2], "wb")) == NULL || fwrite(out, sizeof(double), n * OUT_COLS, fout) != n * OUT_COLS) {
        return 4;
    }
    fclose(fout);
    free(in);
    free(out);
    printf("%s\n", tpm_strerror(TPM_E_SINGULAR_DIRECT));
    return 0;
}
#endif
