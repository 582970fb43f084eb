/* cstab-peer-sundials: what cstab adds to SUNDIALS' own slider-crank example
 * (idasSlCrank_dns.c, shipped by libsundials-dev; patch.cmake includes this
 * file into a build-time copy of it: the example's source is never part of
 * this repository). Options, a trajectory file `cstab score` reads, and the
 * solve's own wall time. docs/peers.md.
 *
 *   cstab-peer-sundials [--problem slider-crank] [--tol TOL] [--t-end T]
 *                       [--every DT] [--out FILE]
 *
 * TOL is the example's relative tolerance (default 1e-6) and TOL/10 its
 * absolute one (the example's 1e-6 / 1e-7); T its horizon (default 10) and
 * DT its output spacing (default 0.4, the example's 25 outputs), T a
 * multiple of DT. FILE: CSV with t, q, x, p, qdot, xdot, pdot (the example's
 * y1..y6, cstab's slider-crank coordinates) at t = 0 and every output, and
 * `# wall_seconds =` the solve's time (IDACreate to the last IDASolve).
 * Without --out it is the example as shipped, apart from the end time being
 * hit exactly. Bad options exit 2 naming the option. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double peer_tol = 1.0e-6, peer_tend = 10.0, peer_every = 0.4;
static int peer_nout = 25, peer_k = 1;
static const char *peer_out = NULL;
static char *peer_buf = NULL;
static size_t peer_len = 0;
static FILE *peer_rows = NULL;
static struct timespec peer_t0, peer_t1;

static int peer_bad(const char *what, const char *value)
{
  fprintf(stderr, "cstab-peer-sundials: %s%s%s\n", what, value ? ": " : "", value ? value : "");
  return 2;
}

/* A finite number > 0, the whole argument. */
static int peer_positive(const char *s, double *v)
{
  char *end = NULL;
  errno = 0;
  *v = strtod(s, &end);
  return end != s && *end == '\0' && errno == 0 && *v > 0 && *v < 1e300;
}

static int peer_args(int argc, char **argv)
{
  int i;
  for (i = 1; i < argc; i++) {
    const char *o = argv[i];
    if (i + 1 >= argc) return peer_bad("option without a value", o);
    const char *v = argv[++i];
    if (strcmp(o, "--problem") == 0) {
      if (strcmp(v, "slider-crank") != 0)
        return peer_bad("this peer models only the problem slider-crank, not", v);
    } else if (strcmp(o, "--tol") == 0) {
      if (!peer_positive(v, &peer_tol)) return peer_bad("--tol must be a number > 0", v);
    } else if (strcmp(o, "--t-end") == 0) {
      if (!peer_positive(v, &peer_tend)) return peer_bad("--t-end must be a number > 0", v);
    } else if (strcmp(o, "--every") == 0) {
      if (!peer_positive(v, &peer_every)) return peer_bad("--every must be a number > 0", v);
    } else if (strcmp(o, "--out") == 0) {
      peer_out = v;
    } else {
      return peer_bad("unknown option (known: --problem, --tol, --t-end, --every, --out)", o);
    }
  }
  double n = peer_tend / peer_every;
  peer_nout = (int)(n + 0.5);
  if (peer_nout < 1 || peer_nout > 10000000 || fabs(peer_nout * peer_every - peer_tend) > 1e-9 * peer_tend)
    return peer_bad("--t-end must be a whole multiple (1 to 1e7) of --every", NULL);
  if (peer_out) {
    peer_rows = open_memstream(&peer_buf, &peer_len);
    if (!peer_rows) return peer_bad("out of memory", NULL);
  }
  return 0;
}

static void peer_row(realtype t, N_Vector y)
{
  const realtype *v = N_VGetArrayPointer(y);
  if (peer_rows)
    fprintf(peer_rows, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", (double)t, (double)v[0], (double)v[1],
            (double)v[2], (double)v[3], (double)v[4], (double)v[5]);
}

/* The trajectory, written whole to FILE.tmp and renamed: a run that fails
 * leaves no partial file. */
static int peer_write(void)
{
  if (!peer_rows) return 0;
  fclose(peer_rows);
  size_t n = strlen(peer_out) + 5;
  char *tmp = malloc(n);
  if (!tmp) return 1;
  snprintf(tmp, n, "%s.tmp", peer_out);
  FILE *f = fopen(tmp, "w");
  if (!f) {
    fprintf(stderr, "cstab-peer-sundials: cannot write %s\n", tmp);
    free(tmp);
    return 1;
  }
  double s = (double)(peer_t1.tv_sec - peer_t0.tv_sec) + 1e-9 * (double)(peer_t1.tv_nsec - peer_t0.tv_nsec);
  fprintf(f, "# SUNDIALS IDAS example idasSlCrank_dns, rtol = %g, atol = %g\n", peer_tol, peer_tol / 10);
  fprintf(f, "# wall_seconds = %.9f\n", s);
  fprintf(f, "t,q,x,p,qdot,xdot,pdot\n");
  fwrite(peer_buf, 1, peer_len, f);
  int bad = ferror(f);
  bad |= fclose(f) != 0;
  if (bad || rename(tmp, peer_out) != 0) {
    fprintf(stderr, "cstab-peer-sundials: cannot write %s\n", peer_out);
    remove(tmp);
    free(tmp);
    return 1;
  }
  free(tmp);
  free(peer_buf);
  return 0;
}
