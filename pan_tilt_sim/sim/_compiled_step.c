/*
 * PyBullet's per-step calls -- velocity motors, joint torques, stepSimulation,
 * getJointStates -- made from C, for pan_tilt_sim.sim.compiled_step.
 *
 * This file is two things at once:
 *
 *  - a CPython extension, pan_tilt_sim.sim._compiled_step;
 *  - a PyBullet plugin (initPlugin_<POSTFIX> ...).  pybullet.loadPlugin() on
 *    this very file hands initPlugin a client of PyBullet's C API that talks
 *    to that simulation's server: the documented way in for compiled code.
 *    dlopen() gives the already-loaded extension back, so the extension sees
 *    the handle that initPlugin received.
 *
 * The C API's functions are taken from the loaded pybullet module with
 * dlsym().  Their declarations and the constants below are those of
 * PhysicsClientC_API.h and SharedMemoryPublic.h in PyBullet 3.2.7, whose C
 * API version is API_VERSION; the Python side uses this file only when
 * pybullet.getAPIVersion() says the same.
 *
 * The commands are the ones pybullet.c sends for the same Python calls, in
 * the same order, with the same values: the results are the same to the
 * last bit (test/sim/test_engine_bit_identity.py runs both).
 *
 * Licensed under the Apache License, Version 2.0.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <dlfcn.h>

#define API_VERSION 202010061
#define POSTFIX "_pan_tilt_sim_compiled_step"

/* Status types (enum EnumSharedMemoryServerStatus) and a control mode. */
enum {
    ACTUAL_STATE_UPDATE_COMPLETED = 21,
    STEP_FORWARD_SIMULATION_COMPLETED = 26,
    SYNC_BODY_INFO_COMPLETED = 66,
    CONTROL_MODE_VELOCITY = 0,
    CONTROL_MODE_TORQUE = 1,
};

typedef struct ClientOpaque *ClientHandle;
typedef struct CommandOpaque *CommandHandle;
typedef struct StatusOpaque *StatusHandle;

struct JointSensorState {
    double position;
    double velocity;
    double reaction[6];
    double motor_torque;
};

/* The first member of struct b3PluginContext: all this plugin reads. */
struct PluginContext {
    ClientHandle client;
};

static struct {
    CommandHandle (*control_init)(ClientHandle, int body, int mode);
    int (*set_torque)(CommandHandle, int dof, double value);
    int (*set_velocity)(CommandHandle, int dof, double value);
    int (*set_kd)(CommandHandle, int dof, double value);
    int (*set_max_force)(CommandHandle, int dof, double value);
    StatusHandle (*submit)(ClientHandle, CommandHandle);
    int (*status_type)(StatusHandle);
    int (*can_submit)(ClientHandle);
    CommandHandle (*step_init)(ClientHandle);
    CommandHandle (*state_init)(ClientHandle, int body);
    int (*joint_state)(ClientHandle, StatusHandle, int joint, struct JointSensorState *);
    CommandHandle (*sync_init)(ClientHandle);
} api;
static int api_bound = 0;

/* The client the last initPlugin call received, until connect() takes it. */
static ClientHandle received = NULL;

__attribute__((visibility("default"))) int initPlugin_pan_tilt_sim_compiled_step(
    struct PluginContext *context)
{
    received = context->client;
    return API_VERSION;
}

__attribute__((visibility("default"))) void exitPlugin_pan_tilt_sim_compiled_step(
    struct PluginContext *context)
{
    (void)context;
}

__attribute__((visibility("default"))) int executePluginCommand_pan_tilt_sim_compiled_step(
    struct PluginContext *context, const void *arguments)
{
    (void)context;
    (void)arguments;
    return -1;
}

/* bind(pybullet_path): take the C API's functions from the loaded pybullet module. */
static PyObject *bind(PyObject *module, PyObject *args)
{
    const char *path;
    if (!PyArg_ParseTuple(args, "s", &path)) {
        return NULL;
    }
    void *library = dlopen(path, RTLD_NOW | RTLD_NOLOAD);
    if (library == NULL) {
        PyErr_Format(PyExc_ImportError, "pybullet is not loaded from %s", path);
        return NULL;
    }
    struct { void **slot; const char *name; } wanted[] = {
        {(void **)&api.control_init, "b3JointControlCommandInit2"},
        {(void **)&api.set_torque, "b3JointControlSetDesiredForceTorque"},
        {(void **)&api.set_velocity, "b3JointControlSetDesiredVelocity"},
        {(void **)&api.set_kd, "b3JointControlSetKd"},
        {(void **)&api.set_max_force, "b3JointControlSetMaximumForce"},
        {(void **)&api.submit, "b3SubmitClientCommandAndWaitStatus"},
        {(void **)&api.status_type, "b3GetStatusType"},
        {(void **)&api.can_submit, "b3CanSubmitCommand"},
        {(void **)&api.step_init, "b3InitStepSimulationCommand"},
        {(void **)&api.state_init, "b3RequestActualStateCommandInit"},
        {(void **)&api.joint_state, "b3GetJointState"},
        {(void **)&api.sync_init, "b3InitSyncBodyInfoCommand"},
    };
    for (size_t k = 0; k < sizeof(wanted) / sizeof(wanted[0]); k++) {
        *wanted[k].slot = dlsym(library, wanted[k].name);
        if (*wanted[k].slot == NULL) {
            dlclose(library);
            PyErr_Format(PyExc_ImportError, "pybullet has no %s", wanted[k].name);
            return NULL;
        }
    }
    /* The module stays loaded as long as Python runs: keep the reference. */
    api_bound = 1;
    Py_RETURN_NONE;
}

/* ---- Connection: the C API client of one PyBullet simulation ---- */

typedef struct {
    PyObject_HEAD
    ClientHandle client; /* NULL once closed */
} Connection;

static PyTypeObject ConnectionType;
static PyTypeObject StepperType;

/* take_connection(): the client the plugin was just given, its body table synced. */
static PyObject *take_connection(PyObject *module, PyObject *unused)
{
    if (!api_bound) {
        PyErr_SetString(PyExc_RuntimeError, "bind() was not called");
        return NULL;
    }
    ClientHandle client = received;
    received = NULL;
    if (client == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "the plugin was not initialised");
        return NULL;
    }
    /* The client learns the bodies loaded so far (b3GetJointState needs the robot's). */
    if (!api.can_submit(client)
        || api.status_type(api.submit(client, api.sync_init(client))) != SYNC_BODY_INFO_COMPLETED) {
        PyErr_SetString(PyExc_RuntimeError, "the plugin's client could not sync the bodies");
        return NULL;
    }
    Connection *connection = PyObject_New(Connection, &ConnectionType);
    if (connection == NULL) {
        return NULL;
    }
    connection->client = client;
    return (PyObject *)connection;
}

static PyObject *connection_close(Connection *self, PyObject *unused)
{
    self->client = NULL;
    Py_RETURN_NONE;
}

static PyObject *connection_closed(Connection *self, void *unused)
{
    return PyBool_FromLong(self->client == NULL);
}

/* ---- Stepper: torques, one step, the joint states ---- */

typedef struct {
    PyObject_HEAD
    Connection *connection;
    int body;
    Py_ssize_t joint_count;
    int *joints;
    Py_ssize_t effort_count;
    int *effort_dofs;
    Py_ssize_t motor_count;
    int *motor_dofs;
} Stepper;

static int *int_array(PyObject *sequence, Py_ssize_t *count, const char *what)
{
    PyObject *fast = PySequence_Fast(sequence, what);
    if (fast == NULL) {
        return NULL;
    }
    *count = PySequence_Fast_GET_SIZE(fast);
    int *values = PyMem_Malloc(sizeof(int) * (size_t)(*count > 0 ? *count : 1));
    if (values == NULL) {
        Py_DECREF(fast);
        PyErr_NoMemory();
        return NULL;
    }
    for (Py_ssize_t k = 0; k < *count; k++) {
        long value = PyLong_AsLong(PySequence_Fast_GET_ITEM(fast, k));
        if (value == -1 && PyErr_Occurred()) {
            PyMem_Free(values);
            Py_DECREF(fast);
            return NULL;
        }
        values[k] = (int)value;
    }
    Py_DECREF(fast);
    return values;
}

/* connection.stepper(body, joints, effort_dofs[, motor_dofs]) */
static PyObject *connection_stepper(Connection *self, PyObject *args)
{
    int body;
    PyObject *joints, *effort_dofs, *motor_dofs = NULL;
    if (!PyArg_ParseTuple(args, "iOO|O", &body, &joints, &effort_dofs, &motor_dofs)) {
        return NULL;
    }
    Stepper *stepper = PyObject_New(Stepper, &StepperType);
    if (stepper == NULL) {
        return NULL;
    }
    stepper->joints = NULL;
    stepper->effort_dofs = NULL;
    stepper->motor_dofs = NULL;
    stepper->motor_count = 0;
    Py_INCREF(self);
    stepper->connection = self;
    stepper->body = body;
    stepper->joints = int_array(joints, &stepper->joint_count, "joints: a sequence of ints");
    if (stepper->joints == NULL) {
        Py_DECREF(stepper);
        return NULL;
    }
    stepper->effort_dofs = int_array(effort_dofs, &stepper->effort_count,
                                     "effort_dofs: a sequence of ints");
    if (stepper->effort_dofs == NULL) {
        Py_DECREF(stepper);
        return NULL;
    }
    if (motor_dofs != NULL) {
        stepper->motor_dofs = int_array(motor_dofs, &stepper->motor_count,
                                        "motor_dofs: a sequence of ints");
        if (stepper->motor_dofs == NULL) {
            Py_DECREF(stepper);
            return NULL;
        }
    }
    return (PyObject *)stepper;
}

static void stepper_dealloc(Stepper *self)
{
    PyMem_Free(self->joints);
    PyMem_Free(self->effort_dofs);
    PyMem_Free(self->motor_dofs);
    Py_XDECREF(self->connection);
    PyObject_Free(self);
}

/* The client a stepper steps; NULL with an exception set once the simulation is gone. */
static ClientHandle open_client(const Stepper *self)
{
    ClientHandle client = self->connection->client;
    if (client == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "the physics client is closed");
    }
    return client;
}

/* One joint's state in ``status``; 0 with an exception set if PyBullet has none. */
static int read_joint(ClientHandle client, StatusHandle status, int joint,
                      struct JointSensorState *state)
{
    if (api.joint_state(client, status, joint, state)) {
        return 1;
    }
    PyErr_Format(PyExc_RuntimeError, "PyBullet gave no state for joint %d", joint);
    return 0;
}

static PyObject *joint_states(ClientHandle client, StatusHandle status, const Stepper *self)
{
    PyObject *states = PyTuple_New(self->joint_count);
    if (states == NULL) {
        return NULL;
    }
    struct JointSensorState state;
    for (Py_ssize_t k = 0; k < self->joint_count; k++) {
        if (!read_joint(client, status, self->joints[k], &state)) {
            Py_DECREF(states);
            return NULL;
        }
        PyObject *reaction = PyTuple_New(6);
        PyObject *row = PyTuple_New(4);
        if (reaction == NULL || row == NULL) {
            Py_XDECREF(reaction);
            Py_XDECREF(row);
            Py_DECREF(states);
            return NULL;
        }
        for (int axis = 0; axis < 6; axis++) {
            PyTuple_SET_ITEM(reaction, axis, PyFloat_FromDouble(state.reaction[axis]));
        }
        PyTuple_SET_ITEM(row, 0, PyFloat_FromDouble(state.position));
        PyTuple_SET_ITEM(row, 1, PyFloat_FromDouble(state.velocity));
        PyTuple_SET_ITEM(row, 2, reaction);
        PyTuple_SET_ITEM(row, 3, PyFloat_FromDouble(state.motor_torque));
        PyTuple_SET_ITEM(states, k, row);
    }
    return states;
}

static int float_item(PyObject *tuple, Py_ssize_t index, double *value)
{
    *value = PyFloat_AsDouble(PyTuple_GET_ITEM(tuple, index));
    return !(*value == -1.0 && PyErr_Occurred());
}

/*
 * ``efforts``, one per effort-driven joint, into ``torques``, read from a
 * snapshot (whatever a number's __float__ does to the sequence); 0 with an
 * exception set if they are not that.
 */
static int read_torques(const Stepper *self, PyObject *efforts, double *torques)
{
    PyObject *values = PySequence_Tuple(efforts);
    if (values == NULL) {
        return 0;
    }
    int ok = PyTuple_GET_SIZE(values) == self->effort_count;
    if (!ok) {
        PyErr_Format(PyExc_ValueError, "%zd efforts for %zd effort-driven joints",
                     PyTuple_GET_SIZE(values), self->effort_count);
    }
    for (Py_ssize_t k = 0; ok && k < self->effort_count; k++) {
        ok = float_item(values, k, &torques[k]);
    }
    Py_DECREF(values);
    return ok;
}

/* Efforts for up to this many joints are converted on the stack. */
#define LOCAL_TORQUES 64

/*
 * The torques on the effort joints, one step, the request for the joint
 * states: the commands pybullet.c sends for setJointMotorControlArray
 * (TORQUE_CONTROL), stepSimulation and getJointStates.  Returns the status
 * holding the states, or NULL with an exception set.
 */
static StatusHandle step_once(const Stepper *self, ClientHandle client, const double *torques)
{
    if (self->effort_count > 0) {
        CommandHandle command = api.control_init(client, self->body, CONTROL_MODE_TORQUE);
        for (Py_ssize_t k = 0; k < self->effort_count; k++) {
            api.set_torque(command, self->effort_dofs[k], torques[k]);
        }
        api.submit(client, command);
    }
    if (api.can_submit(client)) {
        api.submit(client, api.step_init(client));
    }
    StatusHandle status = api.submit(client, api.state_init(client, self->body));
    if (api.status_type(status) != ACTUAL_STATE_UPDATE_COMPLETED) {
        PyErr_SetString(PyExc_RuntimeError, "PyBullet gave no joint states");
        return NULL;
    }
    return status;
}

/* stepper(efforts) -> the joint states after one step, as pybullet.getJointStates gives them */
static PyObject *stepper_call(Stepper *self, PyObject *args, PyObject *kwargs)
{
    PyObject *efforts;
    if (kwargs != NULL && PyDict_GET_SIZE(kwargs) != 0) {
        PyErr_SetString(PyExc_TypeError, "the stepper takes no keyword arguments");
        return NULL;
    }
    if (!PyArg_UnpackTuple(args, "stepper", 1, 1, &efforts)) {
        return NULL;
    }
    double local[LOCAL_TORQUES];
    double *torques = self->effort_count <= LOCAL_TORQUES
        ? local : PyMem_Malloc(sizeof(double) * (size_t)self->effort_count);
    if (torques == NULL) {
        return PyErr_NoMemory();
    }
    /* Nothing is sent unless every effort is a number.  The client is looked up after
       the efforts are read: a number's __float__ may have closed the simulation. */
    ClientHandle client = NULL;
    if (read_torques(self, efforts, torques)) {
        client = open_client(self);
    }
    StatusHandle status = client != NULL ? step_once(self, client, torques) : NULL;
    if (torques != local) {
        PyMem_Free(torques);
    }
    if (status == NULL) {
        return NULL;
    }
    return joint_states(client, status, self);
}

/*
 * ``values``, one per velocity motor, into ``into`` (``what`` names them in the
 * error); 0 with an exception set if they are not that many numbers.
 */
static int read_motor_values(const Stepper *self, PyObject *values, double *into,
                             const char *what)
{
    PyObject *tuple = PySequence_Tuple(values);
    if (tuple == NULL) {
        return 0;
    }
    int ok = PyTuple_GET_SIZE(tuple) == self->motor_count;
    if (!ok) {
        PyErr_Format(PyExc_ValueError, "%zd %s for %zd velocity motors",
                     PyTuple_GET_SIZE(tuple), what, self->motor_count);
    }
    for (Py_ssize_t k = 0; ok && k < self->motor_count; k++) {
        ok = float_item(tuple, k, &into[k]);
    }
    Py_DECREF(tuple);
    return ok;
}

/*
 * stepper.drive(efforts, targets, forces, gains) -> the joint states after one step:
 * the velocity motors of ``motor_dofs`` first (target velocity, maximum force,
 * velocity gain each), as pybullet.c sends setJointMotorControlArray in
 * VELOCITY_CONTROL, then what calling the stepper does.
 */
static PyObject *stepper_drive(Stepper *self, PyObject *args)
{
    PyObject *efforts, *targets, *forces, *gains;
    if (!PyArg_ParseTuple(args, "OOOO", &efforts, &targets, &forces, &gains)) {
        return NULL;
    }
    Py_ssize_t size = (self->effort_count > self->motor_count
                       ? self->effort_count : self->motor_count) + 1;
    double *buffer = PyMem_Malloc(sizeof(double) * (size_t)(4 * size));
    if (buffer == NULL) {
        return PyErr_NoMemory();
    }
    double *torques = buffer, *velocities = buffer + size, *limits = buffer + 2 * size;
    double *kds = buffer + 3 * size;
    ClientHandle client = NULL;
    /* Nothing is sent unless every value is a number; the client looked up last. */
    if (read_torques(self, efforts, torques)
        && read_motor_values(self, targets, velocities, "targets")
        && read_motor_values(self, forces, limits, "forces")
        && read_motor_values(self, gains, kds, "gains")) {
        client = open_client(self);
    }
    PyObject *result = NULL;
    if (client != NULL) {
        if (self->motor_count > 0) {
            CommandHandle command = api.control_init(client, self->body, CONTROL_MODE_VELOCITY);
            for (Py_ssize_t k = 0; k < self->motor_count; k++) {
                api.set_velocity(command, self->motor_dofs[k], velocities[k]);
                api.set_kd(command, self->motor_dofs[k], kds[k]);
                api.set_max_force(command, self->motor_dofs[k], limits[k]);
            }
            api.submit(client, command);
        }
        StatusHandle status = step_once(self, client, torques);
        if (status != NULL) {
            result = joint_states(client, status, self);
        }
    }
    PyMem_Free(buffer);
    return result;
}

/* ---- the controller laws: many steps without Python ---- */

/*
 * A law row, as pan_tilt_sim.controllers.toolbox.step_law lays it out (a list of
 * floats); the loop reads the gains and writes the state back.  Each field
 * and each law kind is named once, in row (code) order, in the lists below:
 * they make the indices (LAW_<field>, <kind>) and the module's LAW_FIELDS,
 * LAW_ROW_SIZE and LAW_KINDS, which pan_tilt_sim.sim.compiled_step compares
 * with step_law's before it uses this file, so that the two cannot part
 * silently.  The names are step_law's.
 */
#define LAW_FIELD_LIST(FIELD)                                                               \
    FIELD(KIND) FIELD(P_GAIN) FIELD(I_GAIN) FIELD(D_GAIN) FIELD(I_CLAMP_MIN) FIELD(I_CLAMP_MAX) \
    FIELD(ANTIWINDUP) FIELD(MAX_VELOCITY) FIELD(EFFORT_LIMIT) FIELD(SETPOINT) FIELD(COMMAND)    \
    FIELD(INTEGRAL) FIELD(OUTPUT) FIELD(LAST_MEASUREMENT) FIELD(UPDATE_STEPS)               \
    FIELD(NEXT_UPDATE) FIELD(PERIOD)
#define LAW_KIND_LIST(KIND) KIND(POSITION_PID) KIND(VELOCITY_PID) KIND(EFFORT)

#define LAW_FIELD_INDEX(name) LAW_##name,
#define LAW_KIND_CODE(name) name,
#define LAW_NAME(name) #name,
enum { LAW_FIELD_LIST(LAW_FIELD_INDEX) LAW_SIZE };
enum { LAW_KIND_LIST(LAW_KIND_CODE) LAW_KINDS };
static const char *const law_field_names[LAW_SIZE] = {LAW_FIELD_LIST(LAW_NAME)};
static const char *const law_kind_names[LAW_KINDS] = {LAW_KIND_LIST(LAW_NAME)};

typedef struct {
    int kind;
    Py_ssize_t effort_slot;
    Py_ssize_t state_slot;
    PyObject *values; /* the row (a list), kept alive by the call's copy of the laws */
    double p, i, d, i_min, i_max, max_velocity, effort_limit;
    int antiwindup;
    double setpoint, command, integral, output, last_measurement;
    /* The controller's clock: an update every `every` steps, the next after `next_update`
       more (0: this step), each with `period` s as its dt (0 in the row: the physics step). */
    Py_ssize_t every, next_update;
    double period;
    double position, velocity; /* the joint's measured state at this step */
} Law;

/*
 * Pid.compute: the integral (clamped, and held at the clamp with
 * antiwindup), then p * error + term - d * rate; a non-finite error or rate
 * gives 0 and leaves the integrator and the last output as they were.
 */
static double pid(Law *law, double error, double rate, double dt)
{
    if (!(-Py_HUGE_VAL < error && error < Py_HUGE_VAL
          && -Py_HUGE_VAL < rate && rate < Py_HUGE_VAL)) {
        return 0.0;
    }
    double integral = law->integral + law->i * error * dt;
    double low = law->i_min, high = law->i_max;
    double term = integral < low ? low : (integral > high ? high : integral);
    law->integral = law->antiwindup ? term : integral;
    double output = law->p * error + term - law->d * rate;
    law->output = output;
    return output;
}

static double clamp_effort(const Law *law, double effort)
{
    double limit = law->effort_limit;
    return effort > limit ? limit : (effort < -limit ? -limit : effort);
}

/*
 * One step of the controller's update, as its Python computes it,
 * operation for operation; returns the effort.
 */
static double law_effort(Law *law, double dt)
{
    if (law->kind == POSITION_PID) {
        /* JointPositionController: the ramp, then the PID with the measured velocity. */
        double max_step = law->max_velocity * dt;
        double setpoint = law->setpoint;
        double delta = law->command - setpoint;
        if (delta > max_step) {
            setpoint += max_step;
        } else if (delta < -max_step) {
            setpoint -= max_step;
        } else {
            setpoint = law->command;
        }
        law->setpoint = setpoint;
        return clamp_effort(law, pid(law, setpoint - law->position, law->velocity, dt));
    }
    if (law->kind == VELOCITY_PID) {
        /* JointVelocityController: the rate is the finite difference of the velocity. */
        double last = law->last_measurement;
        double rate = last != last ? 0.0 : (law->velocity - last) / dt;
        law->last_measurement = law->velocity;
        return clamp_effort(law, pid(law, law->command - law->velocity, rate, dt));
    }
    return law->command; /* JointEffortController */
}

static int store_float(PyObject *list, Py_ssize_t index, double value)
{
    PyObject *number = PyFloat_FromDouble(value);
    if (number == NULL) {
        return 0;
    }
    return PyList_SetItem(list, index, number) == 0; /* steals the reference */
}

/* Read a law's kind, gains, limits and state from a snapshot of its row. */
static int read_row(PyObject *row, Law *law)
{
    double kind, antiwindup, every, next_update;
    if (PyTuple_GET_SIZE(row) != LAW_SIZE) {
        PyErr_Format(PyExc_ValueError, "a law row has %d values, not %zd", LAW_SIZE,
                     PyTuple_GET_SIZE(row));
        return 0;
    }
    if (!float_item(row, LAW_KIND, &kind)) {
        return 0;
    }
    if (!(kind >= 0.0 && kind < LAW_KINDS) || (double)(int)kind != kind) {
        PyErr_Format(PyExc_ValueError, "no law of kind %R", PyTuple_GET_ITEM(row, LAW_KIND));
        return 0;
    }
    law->kind = (int)kind;
    if (!float_item(row, LAW_P_GAIN, &law->p) || !float_item(row, LAW_I_GAIN, &law->i)
        || !float_item(row, LAW_D_GAIN, &law->d)
        || !float_item(row, LAW_I_CLAMP_MIN, &law->i_min)
        || !float_item(row, LAW_I_CLAMP_MAX, &law->i_max)
        || !float_item(row, LAW_ANTIWINDUP, &antiwindup)
        || !float_item(row, LAW_MAX_VELOCITY, &law->max_velocity)
        || !float_item(row, LAW_EFFORT_LIMIT, &law->effort_limit)
        || !float_item(row, LAW_SETPOINT, &law->setpoint)
        || !float_item(row, LAW_COMMAND, &law->command)
        || !float_item(row, LAW_INTEGRAL, &law->integral)
        || !float_item(row, LAW_OUTPUT, &law->output)
        || !float_item(row, LAW_LAST_MEASUREMENT, &law->last_measurement)
        || !float_item(row, LAW_UPDATE_STEPS, &every)
        || !float_item(row, LAW_NEXT_UPDATE, &next_update)
        || !float_item(row, LAW_PERIOD, &law->period)) {
        return 0;
    }
    law->antiwindup = antiwindup != 0.0;
    /* Whole step counts well inside Py_ssize_t, and a period >= 0 (0: the physics step). */
    if (!(every >= 1.0 && every < 1e15) || (double)(Py_ssize_t)every != every
        || !(next_update >= 0.0 && next_update < 1e15)
        || (double)(Py_ssize_t)next_update != next_update
        || !(law->period >= 0.0 && law->period < Py_HUGE_VAL)) {
        PyErr_Format(PyExc_ValueError,
                     "a law's clock is UPDATE_STEPS %R (a whole number >= 1), NEXT_UPDATE %R "
                     "(a whole number >= 0) and PERIOD %R (finite, >= 0)",
                     PyTuple_GET_ITEM(row, LAW_UPDATE_STEPS),
                     PyTuple_GET_ITEM(row, LAW_NEXT_UPDATE), PyTuple_GET_ITEM(row, LAW_PERIOD));
        return 0;
    }
    law->every = (Py_ssize_t)every;
    law->next_update = (Py_ssize_t)next_update;
    return 1;
}

/* Read the joint's position and velocity from a snapshot of its state. */
static int read_state(PyObject *state, Law *law)
{
    PyObject *values = PySequence_Tuple(state);
    if (values == NULL) {
        return 0;
    }
    int ok = PyTuple_GET_SIZE(values) >= 2;
    if (!ok) {
        PyErr_SetString(PyExc_ValueError, "a joint state has a position and a velocity");
    } else {
        ok = float_item(values, 0, &law->position) && float_item(values, 1, &law->velocity);
    }
    Py_DECREF(values);
    return ok;
}

/*
 * Read one law, (effort_slot, state_slot, row); 0 with an exception set if
 * it is malformed.  The rows are read from snapshots (tuples), so that what
 * a number's __float__ might do to them cannot matter.
 */
static int read_law(PyObject *item, const Stepper *self, PyObject *states, Law *law)
{
    PyObject *values;
    if (!PyTuple_Check(item) || !PyArg_ParseTuple(item, "nnO!", &law->effort_slot,
                                                   &law->state_slot, &PyList_Type, &values)) {
        if (!PyErr_Occurred()) {
            PyErr_SetString(PyExc_TypeError, "a law is (effort_slot, state_slot, list)");
        }
        return 0;
    }
    if (law->effort_slot < 0 || law->effort_slot >= self->effort_count
        || law->state_slot < 0 || law->state_slot >= self->joint_count) {
        PyErr_Format(PyExc_ValueError, "law slots %zd, %zd out of range", law->effort_slot,
                     law->state_slot);
        return 0;
    }
    law->values = values; /* alive as long as the call's snapshot of the laws */
    PyObject *row = PyList_AsTuple(values);
    if (row == NULL) {
        return 0;
    }
    int ok = read_row(row, law);
    Py_DECREF(row);
    return ok && read_state(PyTuple_GET_ITEM(states, law->state_slot), law);
}

/*
 * stepper.run_laws(steps, dt, efforts, laws, states) -> (before_last, last)
 *
 * ``steps`` times: each law due at this step computes its effort from the
 * joint's state (the others hold theirs), the torques (``efforts``, the
 * laws' slots overwritten when due), one step, the joint states -- the
 * Python loop's steps with every controller on the physics step's clock one
 * of the laws.
 * ``states`` are the states the first step starts from; the result is the
 * states the last step started from and the states after it.  ``efforts``
 * ends with the last step's torques and each law row with its state.
 */
static PyObject *stepper_run_laws(Stepper *self, PyObject *args)
{
    Py_ssize_t steps;
    double dt;
    PyObject *efforts, *laws, *given_states;
    if (!PyArg_ParseTuple(args, "ndO!O!O", &steps, &dt, &PyList_Type, &efforts, &PyList_Type,
                          &laws, &given_states)) {
        return NULL;
    }
    if (steps < 1 || !(dt > 0.0)) {
        PyErr_SetString(PyExc_ValueError, "steps must be >= 1 and dt > 0");
        return NULL;
    }
    /* Snapshots: what a number's __float__ might do to the arguments cannot matter. */
    PyObject *states = PySequence_Tuple(given_states);
    PyObject *law_items = PyList_AsTuple(laws);
    Law *table = NULL;
    double *torques = NULL;
    PyObject *before = NULL, *after = NULL, *result = NULL;
    if (states == NULL || law_items == NULL) {
        goto done;
    }
    if (PyTuple_GET_SIZE(states) != self->joint_count) {
        PyErr_Format(PyExc_ValueError, "%zd states for %zd joints", PyTuple_GET_SIZE(states),
                     self->joint_count);
        goto done;
    }
    Py_ssize_t law_count = PyTuple_GET_SIZE(law_items);
    table = PyMem_Malloc(sizeof(Law) * (size_t)(law_count > 0 ? law_count : 1));
    torques = PyMem_Malloc(sizeof(double) * (size_t)(self->effort_count + 1));
    if (table == NULL || torques == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    if (!read_torques(self, efforts, torques)) {
        goto done;
    }
    for (Py_ssize_t k = 0; k < law_count; k++) {
        if (!read_law(PyTuple_GET_ITEM(law_items, k), self, states, &table[k])) {
            goto done;
        }
    }
    /* Checked, nothing sent yet (the client looked up last: a number's __float__ may
       have closed the simulation); from here on only PyBullet can fail. */
    ClientHandle client = open_client(self);
    if (client == NULL) {
        goto done;
    }
    Py_INCREF(given_states);
    before = given_states;
    struct JointSensorState state;
    for (Py_ssize_t k = 0; k < law_count; k++) {
        if (table[k].period == 0.0) {
            table[k].period = dt;
        }
    }
    for (Py_ssize_t step = 0; step < steps; step++) {
        for (Py_ssize_t k = 0; k < law_count; k++) {
            Law *law = &table[k];
            if (law->next_update == 0) { /* due: update; otherwise the effort is held */
                torques[law->effort_slot] = law_effort(law, law->period);
                law->next_update = law->every;
            }
            law->next_update--;
        }
        StatusHandle status = step_once(self, client, torques);
        if (status == NULL) {
            goto done;
        }
        if (step + 1 == steps) {
            after = joint_states(client, status, self);
            if (after == NULL) {
                goto done;
            }
            break;
        }
        if (step + 2 == steps) {
            Py_DECREF(before);
            before = joint_states(client, status, self);
            if (before == NULL) {
                goto done;
            }
        }
        for (Py_ssize_t k = 0; k < law_count; k++) {
            Law *law = &table[k];
            if (!read_joint(client, status, self->joints[law->state_slot], &state)) {
                goto done;
            }
            law->position = state.position;
            law->velocity = state.velocity;
        }
    }
    for (Py_ssize_t k = 0; k < self->effort_count; k++) {
        if (!store_float(efforts, k, torques[k])) {
            goto done;
        }
    }
    for (Py_ssize_t k = 0; k < law_count; k++) {
        Law *law = &table[k];
        if (!store_float(law->values, LAW_SETPOINT, law->setpoint)
            || !store_float(law->values, LAW_INTEGRAL, law->integral)
            || !store_float(law->values, LAW_OUTPUT, law->output)
            || !store_float(law->values, LAW_LAST_MEASUREMENT, law->last_measurement)
            || !store_float(law->values, LAW_NEXT_UPDATE, (double)law->next_update)) {
            goto done;
        }
    }
    result = PyTuple_Pack(2, before, after);
done:
    Py_XDECREF(states);
    Py_XDECREF(law_items);
    Py_XDECREF(before);
    Py_XDECREF(after);
    PyMem_Free(table);
    PyMem_Free(torques);
    return result;
}

static PyMethodDef stepper_methods[] = {
    {"drive", (PyCFunction)stepper_drive, METH_VARARGS,
     "drive(efforts, targets, forces, gains) -> states: the velocity motors, then a step"},
    {"run_laws", (PyCFunction)stepper_run_laws, METH_VARARGS,
     "run_laws(steps, dt, efforts, laws, states) -> (before_last, last): "
     "steps with every per-step controller one of the laws"},
    {NULL, NULL, 0, NULL},
};

/* ---- the module ---- */

static PyMethodDef connection_methods[] = {
    {"stepper", (PyCFunction)connection_stepper, METH_VARARGS,
     "stepper(body, joints, effort_dofs): a step function for one robot"},
    {"close", (PyCFunction)connection_close, METH_NOARGS,
     "forget the client (its simulation is going away); steppers then raise"},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef connection_getset[] = {
    {"closed", (getter)connection_closed, NULL, "whether close() was called", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject ConnectionType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "pan_tilt_sim.sim._compiled_step.Connection",
    .tp_basicsize = sizeof(Connection),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The C API client of one PyBullet simulation.",
    .tp_methods = connection_methods,
    .tp_getset = connection_getset,
};

static PyTypeObject StepperType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "pan_tilt_sim.sim._compiled_step.Stepper",
    .tp_basicsize = sizeof(Stepper),
    .tp_dealloc = (destructor)stepper_dealloc,
    .tp_call = (ternaryfunc)stepper_call,
    .tp_methods = stepper_methods,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "stepper(efforts): torques, one step, the joint states.",
};

static PyMethodDef module_methods[] = {
    {"bind", bind, METH_VARARGS, "bind(pybullet_path): take the C API from pybullet"},
    {"take_connection", take_connection, METH_NOARGS,
     "the client the plugin was just given (call right after pybullet.loadPlugin)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_definition = {
    PyModuleDef_HEAD_INIT, "pan_tilt_sim.sim._compiled_step",
    "PyBullet's per-step calls from C (see pan_tilt_sim.sim.compiled_step).", -1,
    module_methods,
};

/* {name: index} for count names; NULL with an exception set on failure. */
static PyObject *name_indices(const char *const *names, int count)
{
    PyObject *indices = PyDict_New();
    for (int k = 0; indices != NULL && k < count; k++) {
        PyObject *index = PyLong_FromLong(k);
        int stored = index != NULL ? PyDict_SetItemString(indices, names[k], index) : -1;
        Py_XDECREF(index);
        if (stored < 0) {
            Py_CLEAR(indices);
        }
    }
    return indices;
}

/*
 * The law layout, for pan_tilt_sim.sim.compiled_step to check against
 * step_law's: LAW_FIELDS {field: row index}, LAW_ROW_SIZE, LAW_KINDS
 * {kind: code}.  0 with an exception set on failure.
 */
static int add_law_layout(PyObject *module)
{
    PyObject *fields = name_indices(law_field_names, LAW_SIZE);
    PyObject *kinds = name_indices(law_kind_names, LAW_KINDS);
    int ok = fields != NULL && kinds != NULL
             && PyModule_AddObjectRef(module, "LAW_FIELDS", fields) == 0
             && PyModule_AddIntConstant(module, "LAW_ROW_SIZE", LAW_SIZE) == 0
             && PyModule_AddObjectRef(module, "LAW_KINDS", kinds) == 0;
    Py_XDECREF(fields);
    Py_XDECREF(kinds);
    return ok;
}

PyMODINIT_FUNC PyInit__compiled_step(void)
{
    if (PyType_Ready(&ConnectionType) < 0 || PyType_Ready(&StepperType) < 0) {
        return NULL;
    }
    PyObject *module = PyModule_Create(&module_definition);
    if (module == NULL) {
        return NULL;
    }
    if (PyModule_AddIntConstant(module, "API_VERSION", API_VERSION) < 0
        || PyModule_AddStringConstant(module, "PLUGIN_POSTFIX", POSTFIX) < 0
        || !add_law_layout(module)) {
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
