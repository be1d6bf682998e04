// LeakSanitizer hook, read once at start-up by sanitized builds (ignored otherwise).
//
// OSMesa (Mesa 22) keeps every framebuffer it ever bound in a process-wide list and never frees it, even after
// OSMesaDestroyContext, so each sanitized program that renders would report a few hundred bytes as leaked. The
// amount is bounded (one small record per buffer size), so it is suppressed here rather than in every run's
// environment. If another module ever needs suppressions, merge them into this one string: the hook can only be
// defined once per program.
extern "C" const char* __lsan_default_suppressions() { return "leak:libOSMesa.so\n"; }
