#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include "model/contact.h"
#include "model/geometry.h"
static void smoke(void **s) {
  (void)s;
  prsm_design d; prsm_design_init(&d);
  d.starts=5; d.pitch_mm=2; d.roller_radius_mm=3.25; d.rollers=10; d.engaged_threads=10;
  prsm_problems e; prsm_problems_init(&e);
  assert_int_equal(prsm_design_resolve(&d,&e),0);
  prsm_flank_pair p; prsm_contact c;
  prsm_flank_pair_nominal(&p,&d,PRSM_SIDE_SCREW);
  int rc=prsm_contact_solve(&c,&p);
  printf("rc %d %.6f %.6f gap %.4f um it %d n %.5f %.5f %.5f k %.5f %.5f\n",rc,c.x_mm,c.y_mm,c.gap_mm*1e3,c.iterations,c.normal[0],c.normal[1],c.normal[2],c.curvature_per_mm[0],c.curvature_per_mm[1]);
  prsm_flank_pair_nominal(&p,&d,PRSM_SIDE_NUT);
  rc=prsm_contact_solve(&c,&p);
  printf("rc %d %.6f %.6g gap %.4f um it %d n %.5f %.5f %.5f k %.5f %.5f\n",rc,c.x_mm,c.y_mm,c.gap_mm*1e3,c.iterations,c.normal[0],c.normal[1],c.normal[2],c.curvature_per_mm[0],c.curvature_per_mm[1]);
}
int main(void){const struct CMUnitTest t[]={cmocka_unit_test(smoke)};return cmocka_run_group_tests(t,NULL,NULL);}
