/* flexsat real-time plant packets, layout version 1 (docs/realtime.md, "The packets").
 *
 * Every packet is little-endian with no padding: a 24-byte header, then the body
 * its type names. The plant serves sensor packets and reads command packets; a
 * client first sends HELLO (a header alone) until the first sensor packet arrives,
 * and answers each sensor packet with one command packet carrying the same
 * sequence, sim_time_ns and (as echo_stamp_ns) plant_stamp_ns. The plant ends a
 * run with END (a header alone). On a big-endian machine swap every field.
 *
 * The Python struct formats of flexsat.realtime.packets are the reference; a test
 * parses this file and checks every size and offset against them.
 */
#ifndef FLEXSAT_PACKETS_H
#define FLEXSAT_PACKETS_H

#include <stdint.h>

#define FLEXSAT_MAGIC 0x54535846u /* "FXST" read as a little-endian uint32 */
#define FLEXSAT_VERSION 1u

#define FLEXSAT_HELLO 1u   /* client ready: header alone */
#define FLEXSAT_SENSOR 2u  /* plant sample: flexsat_sensor_packet */
#define FLEXSAT_COMMAND 3u /* client torque: flexsat_command_packet */
#define FLEXSAT_END 4u     /* end of run: header alone */

#pragma pack(push, 1)

typedef struct {
    uint32_t magic;       /* FLEXSAT_MAGIC */
    uint16_t version;     /* FLEXSAT_VERSION */
    uint16_t type;        /* FLEXSAT_HELLO ... FLEXSAT_END */
    uint32_t sequence;    /* control instant k (a command: the k answered) */
    uint32_t size;        /* the whole packet [bytes] */
    uint64_t sim_time_ns; /* simulated time of the sample [ns] */
} flexsat_header;

typedef struct {
    flexsat_header header;
    uint64_t plant_stamp_ns; /* plant's monotonic clock when sent [ns] */
    double q[4];             /* measured attitude quaternion, scalar first, B rel. N [-] */
    double omega[3];         /* measured body rate, frame B [rad/s] */
} flexsat_sensor_packet;

typedef struct {
    flexsat_header header;
    uint64_t echo_stamp_ns; /* the answered packet's plant_stamp_ns [ns] */
    uint64_t compute_ns;    /* client's time from receipt to sending [ns] */
    double torque[3];       /* commanded body torque, frame B [N m] */
} flexsat_command_packet;

#pragma pack(pop)

#endif /* FLEXSAT_PACKETS_H */
