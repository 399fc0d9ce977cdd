/* alloc_shim.c: the self-tuned loops' allocation and whole-unit rounding of an exported package
 * (its static functions, reached by including the package's source) behind a plain interface,
 * so that tests/export/auto_loop_test.cc compares them with src/control/torque_allocation.cc on
 * problems of its own. */
#include "recruit_controller.c"

int alloc_bundles(void) { return NB; }
int alloc_max_rows(void) { return ROWS; }
int alloc_units(int b) { return recruit_units[b]; }

static void problem(alloc_problem *p, int rows, const double *arms, const double *torque,
                    const double *lo, const double *cap, const double *price) {
  int j, b;
  p->rows = rows;
  for (j = 0; j < rows; ++j) {
    p->torque[j] = torque[j];
    for (b = 0; b < NB; ++b) p->arms[j][b] = arms[j * NB + b];
  }
  for (b = 0; b < NB; ++b) {
    p->floor[b] = lo[b];
    p->cap[b] = cap[b];
    p->price[b] = price[b];
  }
}

/* arms: rows x NB, row-major. */
void alloc_tensions(int rows, const double *arms, const double *torque, const double *lo,
                    const double *cap, const double *price, double *x) {
  alloc_problem p;
  problem(&p, rows, arms, torque, lo, cap, price);
  allocate_tensions(&p, x);
}

void alloc_round(int rows, const double *arms, const double *torque, const double *lo,
                 const double *cap, const double *price, const double *tension,
                 const double *unit_force, double *out) {
  alloc_problem p;
  problem(&p, rows, arms, torque, lo, cap, price);
  round_to_units(&p, tension, unit_force, out);
}
