/* ctc_loop.c: the computed-torque law of tpm_2ppa.c in a 1 kHz control loop against the closed-form forward
 * dynamics (a simulated plant), printing the worst time one control step took. See docs/realtime.md.
 *
 *   tpm-viz export --format c --output gen
 *   cc -std=c99 -O2 -Wall -Wextra -pedantic -I gen examples/ctc_loop.c gen/tpm_2ppa.c -o ctc_loop -lm
 *   ./ctc_loop
 *
 * The plant is the exported model (tpm_forward_dynamics, RK4 with 10 sub-steps per 1 ms sample); the controller
 * (tpm_computed_torque, 10 Hz critically damped, exact model) holds its force for one sample (zero-order hold).
 * The reference is a 50 mm circle at 1 turn per second; the plant starts 5 mm off it. On a refusal the loop
 * keeps the previous command, counts it and goes on (what a drive would do for one sample, docs/realtime.md).
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <time.h>

#include "tpm_2ppa.h"

#ifndef RATE
#define RATE 1000.0      /* controller sample rate [Hz] (cc -DRATE=2000.0 ... to change it) */
#endif
#define SUBSTEPS 10      /* RK4 steps of the plant per sample */
#define SECONDS 3.0      /* length of the run [s] */
#define RADIUS 0.05      /* reference circle [m] */
#define TURN_HZ 1.0      /* turns per second */

static void reference(double t, double p[2], double dp[2], double ddp[2])
{
    const double w = 2.0 * 3.14159265358979323846 * TURN_HZ;
    p[0] = RADIUS * sin(w * t);
    p[1] = RADIUS * (1.0 - cos(w * t));
    dp[0] = RADIUS * w * cos(w * t);
    dp[1] = RADIUS * w * sin(w * t);
    ddp[0] = -RADIUS * w * w * sin(w * t);
    ddp[1] = RADIUS * w * w * cos(w * t);
}

/* x = (p1, p2, dp1, dp2); dx/dt under the held force tau. Returns a tpm code. */
static int plant_rate(const tpm_params *prm, const double x[4], const double tau[2], double dx[4])
{
    double acc[2];
    const int rc = tpm_forward_dynamics(prm, x, x + 2, tau, NULL, acc);
    dx[0] = x[2];
    dx[1] = x[3];
    dx[2] = acc[0];
    dx[3] = acc[1];
    return rc;
}

static int rk4(const tpm_params *prm, double x[4], const double tau[2], double h)
{
    double k1[4], k2[4], k3[4], k4[4], y[4];
    int i, rc = plant_rate(prm, x, tau, k1);
    for (i = 0; i < 4; ++i) y[i] = x[i] + 0.5 * h * k1[i];
    rc |= plant_rate(prm, y, tau, k2);
    for (i = 0; i < 4; ++i) y[i] = x[i] + 0.5 * h * k2[i];
    rc |= plant_rate(prm, y, tau, k3);
    for (i = 0; i < 4; ++i) y[i] = x[i] + h * k3[i];
    rc |= plant_rate(prm, y, tau, k4);
    if (rc != TPM_OK) return rc;
    for (i = 0; i < 4; ++i) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    return TPM_OK;
}

static double seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(void)
{
    /* TPM_PARAMS_EXPORTED also sets the margin (min_cos, min_det): the app's move limits, inside which the dynamics
     * refuse (TPM_E_SINGULAR_*) instead of returning unbounded forces; this circle stays far from it */
    const tpm_params prm = TPM_PARAMS_EXPORTED; /* the plant */
    const tpm_params model = TPM_PARAMS_EXPORTED; /* the controller's model (exact here) */
    const double w = 2.0 * 3.14159265358979323846 * 10.0, zeta = 1.0;
    const double kp[2] = {w * w, w * w}, kd[2] = {2.0 * zeta * w, 2.0 * zeta * w};
    const long samples = (long)(SECONDS * RATE);
    double x[4], p_ref[2], dp_ref[2], ddp_ref[2], tau[2] = {0.0, 0.0};
    double worst = 0.0, total = 0.0, err_last = 0.0, err_late = 0.0;
    long k, refused = 0;
    int s;
    reference(0.0, p_ref, dp_ref, ddp_ref);
    x[0] = p_ref[0] + 0.005;
    x[1] = p_ref[1];
    x[2] = dp_ref[0];
    x[3] = dp_ref[1];
    for (k = 0; k < samples; ++k) {
        const double t = (double)k / RATE;
        double t0, dt;
        int rc;
        reference(t, p_ref, dp_ref, ddp_ref);
        t0 = seconds();
        rc = tpm_computed_torque(&model, kp, kd, p_ref, dp_ref, ddp_ref, x, x + 2, tau); /* tau kept on refusal */
        dt = seconds() - t0;
        refused += rc != TPM_OK;
        worst = dt > worst ? dt : worst;
        total += dt;
        err_last = hypot(p_ref[0] - x[0], p_ref[1] - x[1]);
        if (t >= 1.0 && err_last > err_late) err_late = err_last;
        for (s = 0; s < SUBSTEPS; ++s) {
            rc = rk4(&prm, x, tau, 1.0 / (RATE * SUBSTEPS));
            if (rc != TPM_OK) {
                printf("plant: %s\n", tpm_strerror(rc));
                return 1;
            }
        }
    }
    printf("samples: %ld at %.0f Hz, refused: %ld\n", samples, RATE, refused);
    printf("initial error: 5000.0 um, largest error after 1 s: %.1f um\n", err_late * 1e6);
    printf("control step: mean %.3f us, worst %.3f us\n", total / (double)samples * 1e6, worst * 1e6);
    return refused == 0 ? 0 : 1;
}
