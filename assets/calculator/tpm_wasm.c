/* tpm_wasm.c: the page calculator's way into the generated C (tpm_2ppa.c), compiled with it into tpm_2ppa.wasm
 * by tpm_viz/exchange/c/wasm.py (docs/realtime.md, "The calculator in a page"). Not part of the C export.
 *
 * One exchange buffer of doubles is the module's only state (a page runs one script at a time): the page writes
 * the inputs at TPM_IN, calls tpm_wasm_evaluate() and reads the outputs at TPM_OUT. Every number comes from the
 * generated functions (d from tpm_inverse_kinematics, J from tpm_jacobian, tau from tpm_inverse_dynamics) or, for
 * the quantities the app's panel shows beside them, from the app's own formulas on that d (tpm_viz.app.readouts:
 * c_i = p_i - d_i + a - b, cos th_i = c_i / l_a, sin th_1 = p_2 / l_a, sin th_2 = p_1 / l_a, eqs. 8, 11-12, 23).
 * Which pose the page refuses, and in what words, is the page's script (tpm_calculator.js), on these numbers.
 */
#include "tpm_2ppa.h"

#include <math.h>

/* inputs: the tpm_params fields (its margin included), then p [m], dp [m/s], ddp [m/s^2] */
enum { IN_PRM = 0, IN_P = 9, IN_DP = 11, IN_DDP = 13, IN_COUNT = 15 };
/* outputs: return codes, d [m], cos th_i, sin th_i, th_i [rad], det J_x, det J_q, assembly mode (+1/-1),
 * J row-major, cond J, tau [N] */
enum {
    OUT_RC_IK = 0,
    OUT_RC_J,
    OUT_RC_TAU,
    OUT_D,
    OUT_COS = OUT_D + 2,
    OUT_SIN = OUT_COS + 2,
    OUT_THETA = OUT_SIN + 2,
    OUT_DET_JX = OUT_THETA + 2,
    OUT_DET_JQ,
    OUT_MODE,
    OUT_J,
    OUT_COND = OUT_J + 4,
    OUT_TAU,
    OUT_COUNT = OUT_TAU + 2
};
enum { TPM_IN = 0, TPM_OUT = IN_COUNT, TPM_SIZE = IN_COUNT + OUT_COUNT };

static double io[TPM_SIZE];

/* The exchange buffer: TPM_SIZE doubles, inputs from index 0, outputs from index TPM_OUT (the page reads both
 * numbers from tpm_wasm_layout). */
__attribute__((export_name("tpm_wasm_buffer"))) double *tpm_wasm_buffer(void)
{
    return io;
}

/* (TPM_OUT << 8) | TPM_SIZE: where the outputs start and the buffer's length, in doubles. */
__attribute__((export_name("tpm_wasm_layout"))) int tpm_wasm_layout(void)
{
    return (TPM_OUT << 8) | TPM_SIZE;
}

/* The 2-norm condition number of J = [[1, t1], [t2, 1]] (eq. 10) in closed form: sigma_1 + sigma_2 =
 * sqrt(4 + (t1 - t2)^2), sigma_1 - sigma_2 = |t1 + t2|, sigma_1 sigma_2 = |1 - t1 t2|; inf when singular. */
static double condition(const double J[4])
{
    const double t1 = J[1], t2 = J[2];
    const double sum = sqrt(4.0 + (t1 - t2) * (t1 - t2));
    const double diff = fabs(t1 + t2);
    const double det = fabs(1.0 - t1 * t2);
    return det > 0.0 ? (sum + diff) * (sum + diff) / (4.0 * det) : INFINITY;
}

/* Working-mode actuator positions d of p (eq. 4), as the app finds them (tpm_viz.app.moves.ik_branch): the generated
 * tpm_inverse_kinematics, or, where it refuses |p_j| >= l_a but l_a^2 - p_j^2 is still >= 0 in floating point
 * (|p_j| = l_a to the last bit), the same formula, so the page refuses that pose in the app's words. NaN where the
 * app finds none. Returns the generated function's code. */
static int actuators(const tpm_params *prm, const double p[2], double d[2])
{
    const int rc = tpm_inverse_kinematics(prm, p, d);
    if (rc == TPM_E_UNREACHABLE) {
        const double la2 = prm->l_a * prm->l_a;
        const double r1 = la2 - p[1] * p[1], r2 = la2 - p[0] * p[0];
        d[0] = r1 >= 0.0 ? p[0] + (prm->a - prm->b) - sqrt(r1) : NAN;
        d[1] = r2 >= 0.0 ? p[1] + (prm->a - prm->b) - sqrt(r2) : NAN;
    } else if (rc != TPM_OK) {
        d[0] = d[1] = NAN;
    }
    return rc;
}

/* Every quantity of the page's panel at the state of the buffer's inputs; returns the inverse kinematics' code. */
__attribute__((export_name("tpm_wasm_evaluate"))) int tpm_wasm_evaluate(void)
{
    const double *in = io + TPM_IN;
    double *out = io + TPM_OUT;
    tpm_params prm;
    double d[2], J[4], tau[2];
    int i;
    prm.a = in[0];
    prm.b = in[1];
    prm.l_a = in[2];
    prm.m_a = in[3];
    prm.m_b = in[4];
    prm.m_p = in[5];
    prm.stroke = in[6];
    prm.min_cos = in[7];
    prm.min_det = in[8];
    for (i = 0; i < OUT_COUNT; ++i) {
        out[i] = NAN;
    }
    out[OUT_RC_IK] = actuators(&prm, in + IN_P, d);
    if (!(isfinite(d[0]) && isfinite(d[1]))) {
        return (int)out[OUT_RC_IK];
    }
    for (i = 0; i < 2; ++i) {
        out[OUT_D + i] = d[i];
        out[OUT_COS + i] = ((in[IN_P + i] - d[i]) + (prm.a - prm.b)) / prm.l_a;
        out[OUT_SIN + i] = in[IN_P + 1 - i] / prm.l_a;
        out[OUT_THETA + i] = atan2(out[OUT_SIN + i], out[OUT_COS + i]);
    }
    out[OUT_DET_JQ] = out[OUT_COS] * out[OUT_COS + 1];
    out[OUT_DET_JX] = out[OUT_DET_JQ] - out[OUT_SIN] * out[OUT_SIN + 1];
    {
        const double c1 = (in[IN_P] - d[0]) + (prm.a - prm.b), c2 = (in[IN_P + 1] - d[1]) + (prm.a - prm.b);
        out[OUT_MODE] = c1 * c2 - in[IN_P] * in[IN_P + 1] >= 0.0 ? 1.0 : -1.0;
    }
    out[OUT_RC_J] = tpm_jacobian(&prm, in + IN_P, J);
    if (out[OUT_RC_J] == TPM_OK) {
        for (i = 0; i < 4; ++i) {
            out[OUT_J + i] = J[i];
        }
        out[OUT_COND] = condition(J);
    }
    out[OUT_RC_TAU] = tpm_inverse_dynamics(&prm, in + IN_P, in + IN_DP, in + IN_DDP, 0, tau);
    if (out[OUT_RC_TAU] == TPM_OK) {
        out[OUT_TAU] = tau[0];
        out[OUT_TAU + 1] = tau[1];
    }
    return (int)out[OUT_RC_IK];
}
