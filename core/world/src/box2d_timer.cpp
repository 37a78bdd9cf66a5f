// Box2D's clock, stopped. Box2D times every step, contact update and island solve for
// b2World::GetProfile, which nothing here reads; on Linux each time is a gettimeofday call, and
// those calls took 12-14 % of a simulated step (perf on `train`; docs/world.md, "A control step").
// Box2D's own calls go through the dynamic linker's symbol table (its library exports b2Timer),
// so these definitions, in a library loaded before it, are the ones bound: every profile
// reads 0 ms (World.Box2DsProfileClockIsStopped). Nothing the simulation computes reads a timer,
// so every result is unchanged bit for bit.
#include <box2d/b2_timer.h>

b2Timer::b2Timer() = default;

void b2Timer::Reset() {}

float b2Timer::GetMilliseconds() const { return 0.0f; }
